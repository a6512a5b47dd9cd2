#include "pipeline/direct/parallax_measure.h"

#include <algorithm>
#include <cmath>

#include "pipeline/direct/scene_geometry.h"

namespace px::direct {

namespace {

// Pixels of `from` (depth `from_depth`) whose surface is hidden behind a nearer one in `to`.
int CountOccluded(const cv::Mat& from_depth,
                  const CameraModel& from,
                  const Rigid3& from_cam_from_world,
                  const cv::Mat& to_depth,
                  const CameraModel& to,
                  const Rigid3& to_cam_from_world,
                  double relative_gap) {
  const Rigid3 to_from_from = to_cam_from_world * from_cam_from_world.Inverse();
  const Eigen::Matrix3d r = to_from_from.RotationMatrix();
  const Eigen::Vector3d t = to_from_from.translation;
  int count = 0;
  for (int v = 0; v < from_depth.rows; ++v) {
    const float* row = from_depth.ptr<float>(v);
    for (int u = 0; u < from_depth.cols; ++u) {
      const double z = row[u];
      if (!(z > 0)) continue;
      const Eigen::Vector3d p_from((u - from.cx) / from.fx * z, (v - from.cy) / from.fy * z, z);
      const Eigen::Vector3d p_to = r * p_from + t;
      if (!(p_to.z() > 1e-3)) continue;
      const int x = static_cast<int>(std::lround(to.cx + to.fx * p_to.x() / p_to.z()));
      const int y = static_cast<int>(std::lround(to.cy + to.fy * p_to.y() / p_to.z()));
      if (x < 0 || y < 0 || x >= to_depth.cols || y >= to_depth.rows) continue;
      const float seen = to_depth.at<float>(y, x);
      if (seen > 0 && seen < p_to.z() * (1.0 - relative_gap)) ++count;
    }
  }
  return count;
}

}  // namespace

SceneSamples SceneSamples::FromDepths(const std::vector<View>& views, const std::vector<DepthMap>& depths, int stride) {
  SceneSamples samples;
  stride = std::max(1, stride);
  for (const View& view : views) {
    const DepthMap* depth = FindDepth(depths, view.id);
    if (depth == nullptr || depth->depth_m.type() != CV_32F) continue;
    const bool has_confidence = depth->confidence.size() == depth->depth_m.size() && depth->confidence.type() == CV_32F;
    const Rigid3 world_from_cam = view.cam_from_world.Inverse();
    const CameraModel pinhole = view.camera.WithoutDistortion();
    for (int v = stride / 2; v < depth->depth_m.rows; v += stride) {
      const float* d = depth->depth_m.ptr<float>(v);
      const float* c = has_confidence ? depth->confidence.ptr<float>(v) : nullptr;
      for (int u = stride / 2; u < depth->depth_m.cols; u += stride) {
        if (!(d[u] > 0) || !std::isfinite(d[u]) || (c != nullptr && c[u] < 0.5f)) continue;
        const Eigen::Vector3d p = world_from_cam * (pinhole.Unproject(Eigen::Vector2d(u, v)) * d[u]);
        samples.points_.push_back(p.cast<float>());
        samples.patch_m_.push_back(static_cast<float>(stride * d[u] / pinhole.fx));
      }
    }
  }
  return samples;
}

cv::Mat SceneSamples::DepthSeenFrom(const CameraModel& camera, const Rigid3& cam_from_world, float footprint) const {
  cv::Mat depth(camera.height, camera.width, CV_32F, cv::Scalar(0));
  const Eigen::Matrix3f r = cam_from_world.RotationMatrix().cast<float>();
  const Eigen::Vector3f t = cam_from_world.translation.cast<float>();
  const float fx = static_cast<float>(camera.fx), fy = static_cast<float>(camera.fy);
  const float cx = static_cast<float>(camera.cx), cy = static_cast<float>(camera.cy);
  for (size_t i = 0; i < points_.size(); ++i) {
    const Eigen::Vector3f p = r * points_[i] + t;
    if (!(p.z() > 1e-3f)) continue;
    const float x = cx + fx * p.x() / p.z();
    const float y = cy + fy * p.y() / p.z();
    const float half = 0.5f * std::clamp(footprint * fx * patch_m_[i] / p.z(), 1.0f, 6.0f);
    const int x0 = std::max(0, static_cast<int>(std::floor(x - half + 0.5f)));
    const int x1 = std::min(camera.width - 1, static_cast<int>(std::floor(x + half - 0.5f)));
    const int y0 = std::max(0, static_cast<int>(std::floor(y - half + 0.5f)));
    const int y1 = std::min(camera.height - 1, static_cast<int>(std::floor(y + half - 0.5f)));
    for (int yy = y0; yy <= y1; ++yy) {
      float* row = depth.ptr<float>(yy);
      for (int xx = x0; xx <= x1; ++xx) {
        if (row[xx] == 0 || p.z() < row[xx]) row[xx] = p.z();
      }
    }
  }
  return depth;
}

double ParallaxScore(const SceneSamples& samples,
                     const CameraModel& camera_a,
                     const Rigid3& cam_a_from_world,
                     const CameraModel& camera_b,
                     const Rigid3& cam_b_from_world,
                     double relative_gap) {
  return ParallaxScore(samples.DepthSeenFrom(camera_a, cam_a_from_world),
                       camera_a,
                       cam_a_from_world,
                       samples.DepthSeenFrom(camera_b, cam_b_from_world),
                       camera_b,
                       cam_b_from_world,
                       relative_gap);
}

double ParallaxScore(const cv::Mat& depth_a,
                     const CameraModel& camera_a,
                     const Rigid3& cam_a_from_world,
                     const cv::Mat& depth_b,
                     const CameraModel& camera_b,
                     const Rigid3& cam_b_from_world,
                     double relative_gap) {
  const int a_hidden_in_b =
      CountOccluded(depth_a, camera_a, cam_a_from_world, depth_b, camera_b, cam_b_from_world, relative_gap);
  const int b_hidden_in_a =
      CountOccluded(depth_b, camera_b, cam_b_from_world, depth_a, camera_a, cam_a_from_world, relative_gap);
  return static_cast<double>(a_hidden_in_b) / static_cast<double>(camera_a.width * camera_a.height) +
         static_cast<double>(b_hidden_in_a) / static_cast<double>(camera_b.width * camera_b.height);
}

}  // namespace px::direct
