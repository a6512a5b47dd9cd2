#include "pipeline/calib/triangulation.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

namespace px::calib {

std::optional<Eigen::Vector3d> TriangulatePoint(const std::vector<Rigid3>& cam_from_world,
                                                const std::vector<Eigen::Vector3d>& rays) {
  const size_t n = std::min(cam_from_world.size(), rays.size());
  if (n < 2) return std::nullopt;
  Eigen::MatrixXd a(2 * n, 4);
  for (size_t i = 0; i < n; ++i) {
    if (rays[i].z() <= 0) return std::nullopt;
    const Eigen::Matrix<double, 3, 4> p = cam_from_world[i].Matrix3x4();
    const double x = rays[i].x() / rays[i].z(), y = rays[i].y() / rays[i].z();
    Eigen::RowVector4d row_x = x * p.row(2) - p.row(0);
    Eigen::RowVector4d row_y = y * p.row(2) - p.row(1);
    a.row(2 * i) = row_x / std::max(row_x.norm(), 1e-12);
    a.row(2 * i + 1) = row_y / std::max(row_y.norm(), 1e-12);
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeFullV);
  const Eigen::Vector4d h = svd.matrixV().col(3);
  if (std::abs(h.w()) < 1e-12 * h.head<3>().norm() || !h.allFinite()) return std::nullopt;
  return Eigen::Vector3d(h.head<3>() / h.w());
}

double MaxTriangulationAngleDeg(const Eigen::Vector3d& point_in_world, const std::vector<Rigid3>& cam_from_world) {
  double max_angle = 0;
  for (size_t i = 0; i < cam_from_world.size(); ++i) {
    const Eigen::Vector3d u = point_in_world - CameraCentre(cam_from_world[i]);
    for (size_t j = i + 1; j < cam_from_world.size(); ++j) {
      const Eigen::Vector3d v = point_in_world - CameraCentre(cam_from_world[j]);
      max_angle = std::max(max_angle, std::atan2(u.cross(v).norm(), u.dot(v)));
    }
  }
  return max_angle * 180.0 / M_PI;
}

}  // namespace px::calib
