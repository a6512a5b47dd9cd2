// Consistency between the views' depth maps: a pixel's depth is confirmed when its 3D point,
// projected into another view, lands where that view's depth says the same thing (within a
// disparity tolerance along the baseline between the two). A pixel confirmed by no neighbour is
// wrong in this view or occluded in all the others: either way its depth deserves less trust.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "pipeline/core/view.h"

namespace px::depth {

// CV_8U at views[reference]'s size: 255 where some view in `others` (indices into views, each
// with a depth map in depth_m) confirms depth_m[reference] within tolerance_px of disparity.
// depth_m[k] is CV_32F at views[k]'s size (empty for views without depth; they are skipped).
cv::Mat ConsistentPixels(const std::vector<View>& views,
                         const std::vector<cv::Mat>& depth_m,
                         int reference,
                         const std::vector<int>& others,
                         double tolerance_px);

}  // namespace px::depth
