#include "pipeline/depth/pixel_depth_near_planes.h"

#include <cmath>

#include "pipeline/core/check.h"

namespace px::depth {

int KeepPixelDepthNearPlanes(const cv::Mat& inverse_depth, double max_difference, LayeredDepthView* view) {
  PX_CHECK(inverse_depth.type() == CV_32F && inverse_depth.size() == view->depth_m.size());
  const auto tolerance = static_cast<float>(max_difference);
  int changed = 0;
  for (int y = 0; y < inverse_depth.rows; ++y) {
    const float* u = inverse_depth.ptr<float>(y);
    // A band pixel has a second segment, even where its matte gives that segment no weight.
    const int32_t* behind = view->layers[1].segment.ptr<int32_t>(y);
    float* z = view->depth_m.ptr<float>(y);
    for (int x = 0; x < inverse_depth.cols; ++x) {
      if (u[x] > 0 && z[x] > 0 && behind[x] == SegmentLayer::kNoSegment && std::abs(u[x] - 1.0f / z[x]) <= tolerance) {
        z[x] = 1.0f / u[x];
        ++changed;
      }
    }
  }
  return changed;
}

}  // namespace px::depth
