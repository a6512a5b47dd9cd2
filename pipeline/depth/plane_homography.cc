#include "pipeline/depth/plane_homography.h"

#include <algorithm>
#include <utility>

namespace px::depth {

Eigen::Matrix3d PlaneHomography(const CameraModel& ref,
                                const Rigid3& ref_from_world,
                                const CameraModel& src,
                                const Rigid3& src_from_world,
                                double depth_m) {
  const Rigid3 src_from_ref = src_from_world * ref_from_world.Inverse();
  const Eigen::Matrix3d r = src_from_ref.RotationMatrix();
  const Eigen::Vector3d& t = src_from_ref.translation;
  Eigen::Matrix3d plane = r;
  plane.col(2) += t / depth_m;  // t n^T with n = (0, 0, 1) only touches the third column
  return src.K() * plane * ref.K().inverse();
}

InverseDepthMapping MappingInto(const CameraModel& ref,
                                const Rigid3& ref_from_world,
                                const CameraModel& src,
                                const Rigid3& src_from_world) {
  const Rigid3 src_from_ref = src_from_world * ref_from_world.Inverse();
  InverseDepthMapping mapping;
  mapping.a = src.K() * src_from_ref.RotationMatrix() * ref.K().inverse();
  mapping.b = src.K() * src_from_ref.translation;
  return mapping;
}

std::vector<int> NearestNeighbourViews(const std::vector<View>& views, int reference, int count) {
  constexpr double kSameCentreM = 1e-9;
  const Eigen::Vector3d centre = CameraCentre(views[reference].cam_from_world);
  std::vector<std::pair<double, int>> by_distance;
  for (int i = 0; i < static_cast<int>(views.size()); ++i) {
    if (i == reference) continue;
    const double distance = (CameraCentre(views[i].cam_from_world) - centre).norm();
    if (distance > kSameCentreM) by_distance.emplace_back(distance, i);
  }
  std::stable_sort(
      by_distance.begin(), by_distance.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<int> nearest;
  for (int i = 0; i < std::min(count, static_cast<int>(by_distance.size())); ++i)
    nearest.push_back(by_distance[i].second);
  return nearest;
}

}  // namespace px::depth
