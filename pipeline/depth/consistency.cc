#include "pipeline/depth/consistency.h"

#include <Eigen/Dense>
#include <cmath>

#include "pipeline/core/check.h"
#include "pipeline/depth/view_to_view.h"

namespace px::depth {

cv::Mat ConsistentPixels(const std::vector<View>& views,
                         const std::vector<cv::Mat>& depth_m,
                         int reference,
                         const std::vector<int>& others,
                         double tolerance_px) {
  const View& ref = views[reference];
  const cv::Mat& depth = depth_m[reference];
  PX_CHECK(depth.type() == CV_32F && depth.cols == ref.camera.width && depth.rows == ref.camera.height);
  cv::Mat consistent = cv::Mat::zeros(depth.size(), CV_8U);
  for (int k : others) {
    const cv::Mat& other_depth = depth_m[k];
    if (k == reference || other_depth.empty()) continue;
    const ViewToView projection(ref, views[k]);
    if (projection.focal_baseline() <= 0) continue;
    const double tolerance_inverse = tolerance_px / projection.focal_baseline();
    cv::parallel_for_(cv::Range(0, depth.rows), [&](const cv::Range& rows) {
      for (int y = rows.start; y < rows.end; ++y) {
        const float* z = depth.ptr<float>(y);
        uint8_t* out = consistent.ptr<uint8_t>(y);
        for (int x = 0; x < depth.cols; ++x) {
          if (out[x] || !(z[x] > 0)) continue;
          int u = 0, v = 0;
          double z_other = 0;
          if (!projection.Project(x, y, z[x], &u, &v, &z_other)) continue;
          const float seen = other_depth.at<float>(v, u);
          if (seen > 0 && std::abs(1.0 / z_other - 1.0 / seen) <= tolerance_inverse) out[x] = 255;
        }
      }
    });
  }
  return consistent;
}

}  // namespace px::depth
