#include "pipeline/core/rigid3.h"

#include <algorithm>
#include <cmath>

namespace px {

Rigid3 Rigid3::LookAt(const Eigen::Vector3d& centre_in_world,
                      const Eigen::Vector3d& target_in_world,
                      const Eigen::Vector3d& up_in_world) {
  Eigen::Vector3d z = (target_in_world - centre_in_world).normalized();
  // Camera +y points down in the image, so image "up" is -y.
  Eigen::Vector3d x = (-up_in_world).cross(z);
  if (x.norm() < 1e-9) x = Eigen::Vector3d::UnitX().cross(z);
  x.normalize();
  Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d world_from_cam;
  world_from_cam.col(0) = x;
  world_from_cam.col(1) = y;
  world_from_cam.col(2) = z;
  Eigen::Matrix3d cam_from_world = world_from_cam.transpose();
  return FromMatrix(cam_from_world, -cam_from_world * centre_in_world);
}

Eigen::Matrix<double, 3, 4> Rigid3::Matrix3x4() const {
  Eigen::Matrix<double, 3, 4> m;
  m.leftCols<3>() = RotationMatrix();
  m.col(3) = translation;
  return m;
}

Rigid3 Rigid3::Inverse() const {
  Eigen::Quaterniond inv = rotation.conjugate();
  return Rigid3(inv, -(inv * translation));
}

double RotationErrorDeg(const Rigid3& a, const Rigid3& b) {
  double angle = a.rotation.angularDistance(b.rotation);
  return angle * 180.0 / M_PI;
}

Rigid3 InterpolatePose(const Rigid3& cam_from_world_a, const Rigid3& cam_from_world_b, double t) {
  t = std::clamp(t, 0.0, 1.0);
  Eigen::Quaterniond rotation = cam_from_world_a.rotation.slerp(t, cam_from_world_b.rotation);
  Eigen::Vector3d centre = (1.0 - t) * CameraCentre(cam_from_world_a) + t * CameraCentre(cam_from_world_b);
  return Rigid3(rotation, -(rotation * centre));
}

}  // namespace px
