// Winner-take-all over the plane-sweep cost volume, with parabolic sub-plane refinement and a
// confidence read off the shape of each pixel's cost curve.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace px::depth {

struct PlaneSelection {
  cv::Mat plane;       // CV_32F: refined plane position in [0, num_planes - 1] (fractional)
  cv::Mat confidence;  // CV_32F in [0, 1]
};

// cost_volume[p] is the aggregated cost (CV_32F, [0, kNoDataCost]) of plane p at every pixel.
// The best plane is refined by fitting a parabola (planes are uniform in inverse depth, so the
// fit is in inverse depth): through it and its two neighbours when fit_half_width is 1, or by
// least squares through the five planes around it when 2 (falling back to three points near the
// ends of the range). The wider fit averages out small kinks in the cost curve (each plane keeps
// its own best half of the neighbours) but is biased when the five planes span more than a
// fraction of a pixel, where the cost curve is no longer parabolic. Confidence =
//   (1 - c1/c2) * (1 - c1), clamped to [0, 1],
// with c1 the best cost and c2 the best other local minimum (not adjacent to the best; the
// curve's maximum when there is none): ambiguous curves (repetitive or flat texture) have
// c2 close to c1, poor matches have large c1. Pixels whose best cost is kNoDataCost (no valid
// sample) get confidence 0.
PlaneSelection SelectPlanes(const std::vector<cv::Mat>& cost_volume, int fit_half_width);

}  // namespace px::depth
