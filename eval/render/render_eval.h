// The render evaluation behind `parallax eval render` (paper section 6): novel views rendered by
// the CPU reference renderer, scored with PSNR, SSIM and the hole ratio against
//  - simulated scenes: the ray caster's exact image of any camera, on the Pop9 (3x3) and
//    integral (5x4) lattices, at poses between the lenses, in front of and behind the lattice
//    plane, and turned;
//  - HCI 4D light field: the centre view rendered from its 3x3 ring (and from the whole 9x9)
//    without it;
//  - LLFF forward-facing captures: every 8th view held out (LLFF's protocol) and rendered from
//    the others (published for fern: LLFF 22.85 dB, NeRF 25.17 dB).
// Each case says where the renderer's layered depth came from (EvalDepth): the product's depth
// stage (ComputeLayeredDepth, what a user gets), the simulator's exact depth (the renderer's own
// error, no depth error), or the older plain plane sweep (for comparison with earlier figures).
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "pipeline/core/status.h"
#include "pipeline/depth/depth_options.h"
#include "pipeline/render/layered_from_depth.h"
#include "pipeline/render/render_options.h"
#include "sim/synthetic/sim_camera.h"

namespace px::eval {

// Where a case's layered depth comes from.
enum class EvalDepth {
  kDepthStage,  // ComputeLayeredDepth on the source views: the product's depth (pipeline/run)
  kTruth,       // the simulator's exact depth through LayeredDepthFromDepthMap (sim scenes only)
  kPlaneSweep,  // ComputePlaneSweepDepth + LayeredDepthFromDepthMap (the evaluation's former depth)
};
std::string_view EvalDepthName(EvalDepth depth);            // "depth stage", "exact", "plane sweep"
StatusOr<EvalDepth> ParseEvalDepth(std::string_view name);  // also "stage", "truth", "sweep"

struct RenderEvalCase {
  std::string dataset;    // "sim still_life 3x3", "hci antinous", "llff fern"
  std::string viewpoint;  // "between lenses", "centre from 3x3 ring", "view 8 held out"
  int width = 0;
  int height = 0;
  int num_sources = 0;  // input views given to the renderer
  EvalDepth depth = EvalDepth::kDepthStage;
  double psnr_db = 0;
  double ssim = 0;
  // Where the error is: PSNR over the pixels covered before hole filling, near depth edges (within
  // 3 px of a jump of over 5% in depth: the truth's where known, else the render's) and away from
  // them, and over the filled holes (0 when there are none).
  double psnr_covered_edges_db = 0;
  double psnr_covered_flat_db = 0;
  double psnr_holes_db = 0;
  double hole_ratio = 0;  // before hole filling
  double hole_score = 0;  // H(V), k = 3, at the output size
  // Cracks (crack_measure.h): the fraction of pixels where a farther surface shows through a thin
  // gap (<= 3 px) in a near one that has none; -1 where the dataset has no true depth.
  double crack_fraction = -1;
  // Double images (FrameRender::double_image in regions, image_metrics.h); -1 where not measured.
  double double_image_fraction = -1;
  double render_ms = 0;  // one frame, after a warm-up frame
  // Sequences only (pan_eval.h; the fields above are then means over the frames): TemporalPsnr of
  // the frames against their truths (image_metrics.h). -1 for a single frame.
  double temporal_psnr_db = -1;
};

struct RenderEvalOptions {
  RenderOptions render;
  // The depth sources to evaluate, each a case of its own; kTruth applies to simulated scenes
  // only (skipped elsewhere). Not empty.
  std::vector<EvalDepth> depths = {EvalDepth::kDepthStage, EvalDepth::kTruth};
  // The depth stage's options (its depth range is set per dataset from the scene's bounds).
  DepthOptions depth_stage;
  // How per-pixel depth (exact or plane sweep) becomes the renderer's layered depth.
  LayeredFromDepthOptions layered;
  // Simulated lattices: tile and focal length scale (1 = the product's 640x480 Pop9 tiles and
  // the integral camera's 320x240). (0, 1].
  double sim_scale = 1.0;
  // HCI: also render the centre from all 80 other views of the 9x9 (depth for 80 views: slow).
  bool hci_full_grid = true;
  // LLFF: hold out every n-th view, [2, 100].
  int llff_hold_out_every = 8;
  // When not empty: each case's render, truth, error map (x4) and coverage before hole filling
  // (255 = covered) are written here as PNGs.
  std::filesystem::path dump_dir;
  // Called with a short line as each step starts (may be empty).
  std::function<void(const std::string&)> progress;

  Status Validate() const;
};

// Simulated scene `scene_file` on the lattice `spec` (its distortion, vignetting, noise and
// exposure are ignored: the views are the clean renders with their exact depth).
StatusOr<std::vector<RenderEvalCase>> EvaluateSimulatedScene(const std::filesystem::path& scene_file,
                                                             const SimCameraSpec& spec,
                                                             const RenderEvalOptions& options);

// An HCI 4D light field folder (parameters.cfg, input_CamNNN.png).
StatusOr<std::vector<RenderEvalCase>> EvaluateHciCentreView(const std::filesystem::path& dir,
                                                            const RenderEvalOptions& options);

// An LLFF folder (images_8/, poses_bounds.npy, sparse/0/cameras.bin).
StatusOr<std::vector<RenderEvalCase>> EvaluateLlffHeldOut(const std::filesystem::path& dir,
                                                          const RenderEvalOptions& options);

}  // namespace px::eval
