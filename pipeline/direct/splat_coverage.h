// A cheap H(V) for the valid-viewpoint search (paper 4.2.1). The renderer's Coverage costs about
// a millisecond a probe whatever its size (per-view mesh weights and segment setup); the search
// makes hundreds. Here each view's depth is a subsampled point cloud (SceneSamples), splatted
// with footprint-sized squares into a small target, and H is the paper's distance-transform sum.
//
// It sees what any view saw, while the renderer blends the views nearest each ray, so it can call
// a viewpoint valid that the renderer finds holes in (and, through cracks between splats, the
// reverse): the chosen path is still verified frame by frame through the renderer at the output
// size. `direction_benchmark` prints how often the two agree.
//
// Scaling to the output size, per hole pixel: a hole pixel of the target at distance d (target
// pixels) from the nearest covered one stands for 1 / s^2 output pixels lying about
// (d - 0.5) / s + 0.5 from the covered edge (the edge runs between target pixels). So
// H = sum ((d - 0.5) / s + 0.5)^3 / (w h) over the target's w x h pixels: exact for s = 1,
// d^3 / s^3 for wide holes, and no over-reading of holes one target pixel wide.
#pragma once

#include <vector>

#include "pipeline/core/camera_model.h"
#include "pipeline/core/coverage_report.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/view.h"
#include "pipeline/direct/parallax_measure.h"

namespace px::direct {

// H(V) at the output size from a coverage mask at `scale` of it (CV_8U, non-zero = covered).
double HoleScoreAtOutputSize(const cv::Mat& covered, double scale);

class SplatCoverage {
 public:
  // Every `stride`-th pixel of each view; targets at `scale` of the camera asked for.
  static SplatCoverage FromDepths(const std::vector<View>& views,
                                  const std::vector<DepthMap>& depths,
                                  double scale,
                                  int stride);

  // H(V) at `camera`'s size (report width and height are the camera's), measured at `scale`.
  // Thread-safe.
  CoverageReport Measure(const CameraModel& camera, const Rigid3& cam_from_world) const;
  // Measure as the direction stage's coverage function (the object must outlive it).
  CoverageFunction AsFunction() const;

  size_t points() const { return samples_.size(); }

 private:
  SceneSamples samples_;
  double scale_ = 0.125;
};

}  // namespace px::direct
