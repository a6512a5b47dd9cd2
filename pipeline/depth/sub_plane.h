// Sub-plane refinement of a winner chosen on a smoothed cost volume (semi-global aggregation)
// against the un-smoothed costs: the aggregate picks the right basin, but its path penalties
// flatten the curve's bottom, so a parabola through it is biased towards whole planes. The
// refinement looks for the lowest raw cost within `search_planes` of the winner and fits a
// parabola through it and its two neighbours, or (wide_fit, for plane steps well under a pixel,
// as SelectPlanes) a least-squares parabola through it and two neighbours on each side.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace px::depth {

// `winner` (CV_32F plane positions, whole or fractional) is replaced in place by the refined
// position. `raw` holds one CV_32F cost slice per plane, the winner's size.
void RefineAroundWinners(const std::vector<cv::Mat>& raw, int search_planes, bool wide_fit, cv::Mat* winner);

}  // namespace px::depth
