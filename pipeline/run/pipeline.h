// The capture-to-clip pipeline, stage by stage: split the lattice, make calibrated views,
// compute depth, choose a camera path, render each frame, hand frames to a sink. Pure
// computation: frames in, rendered frames out, plus a report of what each stage did.
#pragma once

#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "pipeline/calib/calib_options.h"
#include "pipeline/calib/photometric.h"
#include "pipeline/calib/rig_refinement_options.h"
#include "pipeline/calib/sfm_options.h"
#include "pipeline/core/coverage_report.h"
#include "pipeline/core/frame_set.h"
#include "pipeline/core/rig_calibration.h"
#include "pipeline/core/view.h"
#include "pipeline/depth/depth_options.h"
#include "pipeline/depth/depth_report.h"
#include "pipeline/direct/camera_path.h"
#include "pipeline/direct/face_detector.h"
#include "pipeline/direct/plan_camera_path.h"
#include "pipeline/direct/shot_file.h"
#include "pipeline/lattice/lattice_options.h"
#include "pipeline/render/gl/backend_scene_renderer.h"
#include "pipeline/render/render_options.h"

namespace px {

// Refinement options with refinement off: views from the factory calibration alone.
inline calib::RigRefinementOptions NoRefinement() {
  calib::RigRefinementOptions options;
  options.enabled = false;
  return options;
}

// Watches a run for the evaluation tools (`parallax eval real`): the views and depth the renderer
// draws, once, then every novel-view frame as rendered, before the sink. Called on the pipeline's
// thread; must not keep references past the call.
class PipelineObserver {
 public:
  virtual ~PipelineObserver() = default;
  virtual void OnScene(const std::vector<View>& /*views*/, const std::vector<DepthMap>& /*depth*/) {}
  virtual void OnFrame(int /*index*/, const VirtualCamera& /*camera*/, const FrameRender& /*frame*/) {}
};

struct PipelineOptions {
  CalibOptions calib;                      // undistortion
  calib::RigRefinementOptions refinement;  // per-shot refinement of a lattice shot
  calib::SfmOptions sfm;                   // structure from motion for image sets (hand-held)
  // Each view's exposure, colour cast and vignetting brought to the centre view's before depth,
  // direction and rendering (a morph included).
  calib::PhotometricOptions photometric;
  // Finding the lattice blind on a lattice frame without a rig calibration: its size when known
  // (0 = found blind) and how its tiles lie (upright for a photo of a lattice; the recording's
  // source.lattice says, see device/clip_job.h).
  LatticeOptions lattice;
  DepthOptions depth;    // depth range 0 = the rig's nominal range
  DirectOptions direct;  // move, effect, seed, duration, fps, subjects, search
  RenderOptions render;
  // Which renderer draws the clip: auto (GL on a GPU, else the faster one here: the CPU), cpu,
  // egl or osmesa; a GL back end that cannot start or draw falls back to the CPU with the reason.
  render::gl::RenderBackendOptions render_backend;
  int num_threads = 0;  // 0 = all cores
  // Hand-held photos (an image set) larger than this on their longer side are scaled down to it
  // before calibration, depth and rendering, so the clip is this size too (image_set_scale.h).
  // 1200: a 3:2 photo gives a 1200x800 clip. 0 = full size, else [64, 16384].
  int image_set_max_side_px = 1200;
  // Loaded by device/ (the pipeline opens no files) and shared between runs.
  std::shared_ptr<const direct::FaceDetector> face_detector;  // null: no face detection
  std::shared_ptr<const direct::Shot> shot;                   // null: the taxonomy chooses
  PipelineObserver* observer = nullptr;                       // not owned; null: nobody watches
  Status Validate() const;
};

// Receives rendered frames in order (the clip encoder, a PNG writer, a test).
class FrameSink {
 public:
  virtual ~FrameSink() = default;
  // Once, with the path about to be rendered, before the first frame (a sink may choose its
  // poster frame from it).
  virtual void Begin(const CameraPath& path) { (void)path; }
  virtual Status Consume(int index, const cv::Mat& bgr) = 0;
};

struct StageTiming {
  std::string stage;  // "lattice", "calib", "depth", "direct", "render", "encode"
  double ms = 0;
};

struct PipelineReport {
  int num_views = 0;  // usable views after splitting and checks
  // Calibration: "factory", "factory (confirmed by refinement)", "refined" (per-shot
  // refinement) or "structure from motion"; the refinement's or SfM's figures in one line (matches, inliers, RMS before
  // and after).
  std::string calibration;
  std::string calibration_summary;
  std::string photometric;            // what the photometric equalisation changed, per view
  std::vector<std::string> warnings;  // degraded results, for the log and the clip's JSON
  // Per stage, wall time. "encode" is the frame sink's own time on its thread (it overlaps
  // "render", which leaves out the waits for the sink).
  std::vector<StageTiming> timings;
  CameraPath path;                             // the path rendered
  DirectionReport direction;                   // subjects, the move's choice, fallbacks, search figures
  int frames_rendered = 0;                     // frames given to the sink
  int frames_reused = 0;                       // of which shown again from an earlier drawing (a hold, a way back)
  double mean_hole_ratio = 0;                  // fraction of pixels no source covered, before filling
  std::vector<CoverageReport> frame_coverage;  // per rendered frame: hole ratio and H(V) before filling
  DepthReport depth;                           // per view: confident fraction, low-confidence mask, disagreement
  // The scene renderer's back end ("cpu", "gl-osmesa", "gl-egl"; empty for an image set that
  // could not be calibrated), which drew the coverage probes and any novel-view frames, and why
  // (asked for, found, or the fallback's reason).
  std::string render_backend;
  std::string render_backend_reason;
};

// stage: a short name; fraction: 0..1 within that stage. Return false to cancel.
using ProgressCallback = std::function<bool(const std::string& stage, double fraction)>;

// Builds calibrated, undistorted views from a capture and its rig calibration. A lattice capture
// uses its first frame whose status is ok (others are named in `warnings`) and fails, naming the
// frame, when none is; views whose tile is blank (a covered or dead lens) are dropped with a
// warning while at least two remain. The lattice's calibration is the factory's (`rig`) unless
// per-shot refinement is enabled in `refinement` (off by default here; RunPipeline refines).
// Image sets (hand-held) get their poses and focal lengths from structure from motion (`sfm`):
// `rig` then gives intrinsics only when it has one lens per image of the image's size; a set
// that cannot be reconstructed fails with FAILED_PRECONDITION and the reason.
// (RunPipeline then morphs between two images or pans over one: see below).
StatusOr<std::vector<View>> MakeViewsFromCapture(const FrameSet& capture,
                                                 const RigCalibration& rig,
                                                 std::vector<std::string>* warnings,
                                                 const CalibOptions& calib = {},
                                                 const calib::RigRefinementOptions& refinement = NoRefinement(),
                                                 const calib::SfmOptions& sfm = {});

// Runs every stage and hands each rendered frame to `sink` in order. Timings: "lattice",
// "calib", "depth", "direct", "render" (rendering only) and "encode" (time inside the sink).
// Never fails the button for untrustworthy input: with depth it cannot trust, or an image set it
// cannot calibrate, the direction stage falls back to a morph between two views or a flat pan
// and zoom, and the report's warnings say why.
// progress is called at each stage's start and end and after each rendered frame; returning
// false stops the run with CANCELLED.
StatusOr<PipelineReport> RunPipeline(const FrameSet& capture,
                                     const RigCalibration& rig,
                                     const PipelineOptions& options,
                                     FrameSink* sink,
                                     const ProgressCallback& progress = {});

// The scene a clip is drawn from, for the interactive preview of authoring (device/preview):
// RunPipeline's stages 1 to 3 (lattice, calibration, photometric equalisation, depth), the views
// that match none of the others dropped, exactly as RunPipeline draws from them.
struct PipelineScene {
  std::vector<View> views;
  std::vector<DepthMap> depth_maps;
  std::vector<LayeredDepthView> layers;
  PipelineReport report;  // calibration, depth, warnings and timings of those stages
};
// FAILED_PRECONDITION, with the reason, when the capture cannot be calibrated (RunPipeline would
// morph or pan over it instead).
StatusOr<PipelineScene> BuildPipelineScene(const FrameSet& capture,
                                           const RigCalibration& rig,
                                           const PipelineOptions& options,
                                           const ProgressCallback& progress = {});

}  // namespace px
