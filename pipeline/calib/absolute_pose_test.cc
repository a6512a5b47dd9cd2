#include "pipeline/calib/absolute_pose.h"

#include <gtest/gtest.h>

#include <cstdio>

#include "pipeline/calib/geometry_test_util.h"

namespace px::calib {
namespace {

using testing::NoisyRay;
using testing::RandomPoints;
using testing::RandomRay;
using testing::SmallRotation;

class AbsolutePoseSolverTest : public ::testing::TestWithParam<AbsolutePoseSolver> {};

TEST_P(AbsolutePoseSolverTest, RecoversKnownPoseWithOutliers) {
  cv::RNG rng(21);
  const Rigid3 cam_from_world(SmallRotation(3.0, -5.0, 2.0), Eigen::Vector3d(0.1, -0.05, 0.2));
  const std::vector<Eigen::Vector3d> points = RandomPoints(150, 1.0, 1.5, 5.0, rng);
  std::vector<Eigen::Vector3d> rays;
  std::vector<bool> outlier;
  for (const Eigen::Vector3d& p : points) {
    outlier.push_back(rng.uniform(0.0, 1.0) < 0.3);
    rays.push_back(outlier.back() ? RandomRay(rng) : NoisyRay(cam_from_world, p, 600.0, 0.3, rng));
  }
  RansacOptions options;
  options.focal_px = 600;
  options.max_error_px = 1.5;
  const AbsolutePoseResult result = EstimateAbsolutePose(rays, points, GetParam(), options);
  ASSERT_TRUE(result.success) << result.failure;
  const double rotation_error = RotationErrorDeg(result.cam_from_world, cam_from_world);
  const double centre_error = (CameraCentre(result.cam_from_world) - CameraCentre(cam_from_world)).norm();
  int wrong = 0;
  for (int i : result.inliers) wrong += outlier[i] ? 1 : 0;
  std::printf("absolute pose: %zu inliers (%d outliers), rotation error %.4f deg, centre error %.2f mm\n",
              result.inliers.size(),
              wrong,
              rotation_error,
              1000 * centre_error);
  EXPECT_LT(rotation_error, 0.05);
  EXPECT_LT(centre_error, 0.005);
  EXPECT_GT(result.inliers.size(), 90u);
  EXPECT_LE(wrong, 2);
}

INSTANTIATE_TEST_SUITE_P(Solvers,
                         AbsolutePoseSolverTest,
                         ::testing::Values(AbsolutePoseSolver::kP3p, AbsolutePoseSolver::kEpnp));

TEST(AbsolutePoseTest, TooFewCorrespondencesFailWithAReason) {
  const AbsolutePoseResult result =
      EstimateAbsolutePose({Eigen::Vector3d(0, 0, 1)}, {Eigen::Vector3d(0, 0, 2)}, AbsolutePoseSolver::kP3p, {});
  EXPECT_FALSE(result.success);
  EXPECT_EQ(result.failure, "1 2D-3D correspondences, need at least 6");
}

}  // namespace
}  // namespace px::calib
