// Leave-one-out novel views on a real capture (LLFF's protocol): every held-out view in turn is
// rendered from the other views at the pose the product's calibration gave it (all views posed
// together, by structure from motion) and compared with the photo itself. Beside ours, on the same
// pixels, two baselines: the nearest other view as it is, and that view warped onto the held-out
// one by a single plane fitted to its depth (what a homography-based "3D photo" would show).
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "eval/real/real_set.h"
#include "pipeline/calib/photometric.h"
#include "pipeline/calib/sfm_options.h"
#include "pipeline/core/status.h"
#include "pipeline/depth/depth_options.h"
#include "pipeline/render/render_options.h"

namespace px::eval {

struct ImageScores {
  double psnr_db = 0;
  double ssim = 0;
  double psnr_edges_db = 0;  // over the edge band (pixels near a depth edge of our render)
};

struct LeaveOneOutCase {
  int view = 0;  // the frame held out
  std::string view_name;
  int num_sources = 0;
  int nearest_view = -1;  // the nearest other view by camera centre: the baselines' source
  ImageScores ours;
  ImageScores nearest;   // the nearest view unwarped
  ImageScores plane;     // the nearest view warped by its best-fit plane
  double invented = 0;   // share of our pixels that no source covered (inpainted)
  double edge_band = 0;  // share of the frame in the edge band
  double depth_ms = 0;
  double render_ms = 0;
};

struct LeaveOneOutResult {
  std::string set;
  int num_views = 0;
  int num_posed = 0;
  std::string calibration;  // the calibration's summary line
  std::vector<LeaveOneOutCase> cases;
  std::vector<std::string> notes;  // views that were not posed, held-out views not scored, and why
};

struct LeaveOneOutOptions {
  DepthOptions depth;  // depth range 0: the calibration's
  RenderOptions render;
  calib::SfmOptions sfm;
  // The views (the held-out one included, as the product would have it) equalised to the centre
  // view's exposure, colour and vignetting before depth and scoring, as the product does.
  calib::PhotometricOptions photometric;
  int max_side_px = 1200;  // photos are processed at this longer side, as the product does
  int edge_band_px = 3;    // the edge band's half-width
  // When not empty: per case, the photo, ours, both baselines and their error maps as one PNG.
  std::filesystem::path dump_dir;
  std::function<void(const std::string&)> progress;  // a line as each step starts (may be empty)
};

// FAILED_PRECONDITION (the set cannot be scored) when it has fewer than 3 views or fewer than 3
// are posed; the reason names the set.
StatusOr<LeaveOneOutResult> EvaluateLeaveOneOut(const RealSet& set, const LeaveOneOutOptions& options);

// Means over a result's cases.
ImageScores MeanScores(const std::vector<LeaveOneOutCase>& cases, ImageScores LeaveOneOutCase::*which);
struct LeaveOneOutMeans {
  ImageScores ours, nearest, plane;
  double invented = 0;
};
LeaveOneOutMeans Means(const LeaveOneOutResult& result);

}  // namespace px::eval
