#include "pipeline/calib/reprojection_cost.h"

#include <Eigen/Geometry>

namespace px::calib {

bool AnalyticReprojectionCost::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  const double* q = parameters[0];  // w, x, y, z
  const double* centre = parameters[1];
  const double* intrinsics = parameters[2];
  const double* point = parameters[3];
  const Eigen::Vector3d offset(point[0] - centre[0], point[1] - centre[1], point[2] - centre[2]);
  double p_array[3];
  ceres::UnitQuaternionRotatePoint(q, offset.data(), p_array);
  const Eigen::Vector3d p(p_array);
  const double inverse_z = 1.0 / p.z();
  const double x = p.x() * inverse_z, y = p.y() * inverse_z;
  const double r2 = x * x + y * y;
  const double k1 = intrinsics[kK1], k2 = intrinsics[kK2], k3 = terms_.k3, p1 = terms_.p1, p2 = terms_.p2;
  const double radial = 1.0 + k1 * r2 + k2 * r2 * r2 + k3 * r2 * r2 * r2;
  const double xd = x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x);
  const double yd = y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y;
  const double focal = intrinsics[kFocal], focal_y = focal * terms_.aspect;
  residuals[0] = focal * xd + intrinsics[kCx] - terms_.u;
  residuals[1] = focal_y * yd + intrinsics[kCy] - terms_.v;
  if (jacobians == nullptr) return true;

  // d(residual) / d(p), through the normalised point (x, y) and the distortion.
  const double d_radial = k1 + 2 * k2 * r2 + 3 * k3 * r2 * r2;
  const double dxd_dx = radial + 2 * x * x * d_radial + 2 * p1 * y + 6 * p2 * x;
  const double dxd_dy = 2 * x * y * d_radial + 2 * p1 * x + 2 * p2 * y;
  const double dyd_dx = dxd_dy;
  const double dyd_dy = radial + 2 * y * y * d_radial + 6 * p1 * y + 2 * p2 * x;
  Eigen::Matrix<double, 2, 2> d_distorted;
  d_distorted << focal * dxd_dx, focal * dxd_dy, focal_y * dyd_dx, focal_y * dyd_dy;
  Eigen::Matrix<double, 2, 3> d_normalised;
  d_normalised << inverse_z, 0, -x * inverse_z, 0, inverse_z, -y * inverse_z;
  const Eigen::Matrix<double, 2, 3> d_p = d_distorted * d_normalised;

  using RowMajor2x3 = Eigen::Matrix<double, 2, 3, Eigen::RowMajor>;
  if (jacobians[0] != nullptr) {
    // p = q (0, o) q*: d p / d w = 2 (w o + v x o), d p / d v = 2 (v.o I + v o^T - o v^T - w [o]x).
    const double w = q[0];
    const Eigen::Vector3d vec(q[1], q[2], q[3]);
    Eigen::Matrix3d o_cross;
    o_cross << 0, -offset.z(), offset.y(), offset.z(), 0, -offset.x(), -offset.y(), offset.x(), 0;
    Eigen::Matrix<double, 3, 4> d_rotation;
    d_rotation.col(0) = 2 * (w * offset + vec.cross(offset));
    d_rotation.rightCols<3>() = 2 * (vec.dot(offset) * Eigen::Matrix3d::Identity() + vec * offset.transpose() -
                                     offset * vec.transpose() - w * o_cross);
    Eigen::Map<Eigen::Matrix<double, 2, 4, Eigen::RowMajor>> d_quaternion(jacobians[0]);
    d_quaternion = d_p * d_rotation;
  }
  if (jacobians[1] != nullptr || jacobians[3] != nullptr) {
    Eigen::Matrix<double, 3, 3, Eigen::RowMajor> rotation;
    ceres::QuaternionToRotation(q, rotation.data());
    const Eigen::Matrix<double, 2, 3> d_point = d_p * rotation;
    if (jacobians[1] != nullptr) Eigen::Map<RowMajor2x3>{jacobians[1]} = -d_point;
    if (jacobians[3] != nullptr) Eigen::Map<RowMajor2x3>{jacobians[3]} = d_point;
  }
  if (jacobians[2] != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 2, kIntrinsicsSize, Eigen::RowMajor>> d_intrinsics(jacobians[2]);
    d_intrinsics << xd, 1, 0, focal * x * r2, focal * x * r2 * r2,  //
        terms_.aspect * yd, 0, 1, focal_y * y * r2, focal_y * y * r2 * r2;
  }
  return true;
}

}  // namespace px::calib
