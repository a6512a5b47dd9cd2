// Rigid transforms, named b_from_a: p_in_b = b_from_a * p_in_a (colmap's convention).
// Frames: world (rig), cam (OpenCV: x right, y down, z forward). Units are metres.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace px {

struct Rigid3 {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Rigid3() = default;
  Rigid3(const Eigen::Quaterniond& r, const Eigen::Vector3d& t) : rotation(r.normalized()), translation(t) {}
  static Rigid3 FromMatrix(const Eigen::Matrix3d& r, const Eigen::Vector3d& t) {
    return Rigid3(Eigen::Quaterniond(r), t);
  }
  // The camera whose centre is `centre_in_world`, looking at `target_in_world`, with image "up"
  // as close as possible to `up_in_world` (OpenCV camera: +y is down in the image).
  static Rigid3 LookAt(const Eigen::Vector3d& centre_in_world,
                       const Eigen::Vector3d& target_in_world,
                       const Eigen::Vector3d& up_in_world = Eigen::Vector3d(0, -1, 0));

  Eigen::Matrix3d RotationMatrix() const { return rotation.toRotationMatrix(); }
  Eigen::Matrix<double, 3, 4> Matrix3x4() const;
  Rigid3 Inverse() const;
  Eigen::Vector3d operator*(const Eigen::Vector3d& p_in_a) const { return rotation * p_in_a + translation; }
  // c_from_a = c_from_b * b_from_a
  Rigid3 operator*(const Rigid3& b_from_a) const {
    return Rigid3(rotation * b_from_a.rotation, rotation * b_from_a.translation + translation);
  }
};

// For a cam_from_world transform: the camera centre in world coordinates.
inline Eigen::Vector3d CameraCentre(const Rigid3& cam_from_world) {
  return -(cam_from_world.rotation.conjugate() * cam_from_world.translation);
}

// Angle of the relative rotation in degrees, and distance between translations.
double RotationErrorDeg(const Rigid3& a, const Rigid3& b);

// Interpolates two cam_from_world poses: the camera centre moves on the straight line between
// the two centres and the orientation by slerp; t in [0, 1].
Rigid3 InterpolatePose(const Rigid3& cam_from_world_a, const Rigid3& cam_from_world_b, double t);

}  // namespace px
