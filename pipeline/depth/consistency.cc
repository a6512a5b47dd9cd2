#include "pipeline/depth/consistency.h"

#include <Eigen/Dense>
#include <cmath>

#include "pipeline/core/check.h"

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
  const Rigid3 world_from_ref = ref.cam_from_world.Inverse();
  for (int k : others) {
    const cv::Mat& other_depth = depth_m[k];
    if (k == reference || other_depth.empty()) continue;
    const View& other = views[k];
    const Rigid3 other_from_ref = other.cam_from_world * world_from_ref;
    const Eigen::Matrix3d r = other_from_ref.RotationMatrix();
    const Eigen::Vector3d t = other_from_ref.translation;
    // Disparity of inverse depth u in `other` is about focal * baseline * u.
    const double focal_baseline = other.camera.fx * t.norm();
    if (focal_baseline <= 0) continue;
    const double tolerance_inverse = tolerance_px / focal_baseline;
    const CameraModel& a = ref.camera;
    const CameraModel& b = other.camera;
    cv::parallel_for_(cv::Range(0, depth.rows), [&](const cv::Range& rows) {
      for (int y = rows.start; y < rows.end; ++y) {
        const float* z = depth.ptr<float>(y);
        uint8_t* out = consistent.ptr<uint8_t>(y);
        for (int x = 0; x < depth.cols; ++x) {
          if (out[x] || !(z[x] > 0)) continue;
          const Eigen::Vector3d p_ref((x - a.cx) / a.fx * z[x], (y - a.cy) / a.fy * z[x], z[x]);
          const Eigen::Vector3d p = r * p_ref + t;
          if (p.z() <= 0) continue;
          const int u = static_cast<int>(std::lround(b.fx * p.x() / p.z() + b.cx));
          const int v = static_cast<int>(std::lround(b.fy * p.y() / p.z() + b.cy));
          if (u < 0 || v < 0 || u >= other_depth.cols || v >= other_depth.rows) continue;
          const float seen = other_depth.at<float>(v, u);
          if (seen > 0 && std::abs(1.0 / p.z() - 1.0 / seen) <= tolerance_inverse) out[x] = 255;
        }
      }
    });
  }
  return consistent;
}

}  // namespace px::depth
