// Occlusion-robust aggregation of the neighbours' matching costs for one plane.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace px::depth {

struct AggregationWorkspace {
  std::vector<float> sorted;  // num_neighbours rows of one image row
};

// Per pixel, the mean of the best half (rounded up) of the neighbours' valid costs (those below
// kInvalidCost), or kNoDataCost where none is valid. A point occluded in some neighbours is
// still matched by the others; dropping the worst half also drops those occluded costs.
// costs: 1 to 16 CV_32F maps of equal size; aggregated: CV_32F of that size.
void AggregateBestHalf(const std::vector<cv::Mat>& costs, AggregationWorkspace* workspace, cv::Mat* aggregated);

}  // namespace px::depth
