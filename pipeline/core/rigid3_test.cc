#include "pipeline/core/rigid3.h"

#include <gtest/gtest.h>

namespace px {
namespace {

TEST(Rigid3Test, ComposeAndInverse) {
  Rigid3 b_from_a(Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY())), {0.1, -0.2, 0.5});
  Rigid3 c_from_b(Eigen::Quaterniond(Eigen::AngleAxisd(-0.7, Eigen::Vector3d::UnitX())), {1.0, 0.0, -0.3});
  Eigen::Vector3d p_in_a(0.4, 0.5, 2.0);
  Eigen::Vector3d via_b = c_from_b * (b_from_a * p_in_a);
  EXPECT_TRUE(((c_from_b * b_from_a) * p_in_a).isApprox(via_b, 1e-12));
  EXPECT_TRUE((b_from_a.Inverse() * (b_from_a * p_in_a)).isApprox(p_in_a, 1e-12));
}

TEST(Rigid3Test, LookAtPointsTheOpticalAxisAtTheTarget) {
  Eigen::Vector3d centre(0.5, -0.2, -1.0), target(0.0, 0.0, 3.0);
  Rigid3 cam_from_world = Rigid3::LookAt(centre, target);
  EXPECT_TRUE(CameraCentre(cam_from_world).isApprox(centre, 1e-12));
  Eigen::Vector3d target_in_cam = cam_from_world * target;
  EXPECT_NEAR(target_in_cam.x(), 0.0, 1e-12);
  EXPECT_NEAR(target_in_cam.y(), 0.0, 1e-12);
  EXPECT_GT(target_in_cam.z(), 0.0);
  // World "up" (-y) stays up in the image.
  Eigen::Vector3d above_in_cam = cam_from_world * (target + Eigen::Vector3d(0, -1, 0));
  EXPECT_LT(above_in_cam.y(), 0.0);
}

TEST(Rigid3Test, InterpolatePoseMovesTheCentreOnAStraightLine) {
  Rigid3 a = Rigid3::LookAt({-1, 0, 0}, {0, 0, 5});
  Rigid3 b = Rigid3::LookAt({1, 0, 0}, {0, 0, 5});
  Rigid3 mid = InterpolatePose(a, b, 0.5);
  EXPECT_TRUE(CameraCentre(mid).isApprox(Eigen::Vector3d(0, 0, 0), 1e-12) || CameraCentre(mid).norm() < 1e-12);
  EXPECT_LT(RotationErrorDeg(mid, Rigid3::LookAt({0, 0, 0}, {0, 0, 5})), 1e-6);
}

}  // namespace
}  // namespace px
