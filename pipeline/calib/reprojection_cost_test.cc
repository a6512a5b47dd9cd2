#include "pipeline/calib/reprojection_cost.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

namespace px::calib {
namespace {

using Jacobian = Eigen::Matrix<double, 2, Eigen::Dynamic, Eigen::RowMajor>;

// Residual and Jacobians of one cost at one set of parameters.
struct Evaluation {
  Eigen::Vector2d residual;
  Jacobian rotation = Jacobian(2, 4), centre = Jacobian(2, 3), intrinsics = Jacobian(2, kIntrinsicsSize),
           point = Jacobian(2, 3);
};

Evaluation Evaluate(const ceres::CostFunction& cost, const double* const* parameters) {
  Evaluation e;
  double* jacobians[4] = {e.rotation.data(), e.centre.data(), e.intrinsics.data(), e.point.data()};
  EXPECT_TRUE(cost.Evaluate(parameters, e.residual.data(), jacobians));
  return e;
}

// The analytic Jacobians agree with automatic differentiation of the reference residual: exactly
// for centre, intrinsics and point, and for the rotation along the quaternion manifold's tangent
// (the only directions the solver moves in), over random cameras with every distortion term set.
TEST(ReprojectionCostTest, AnalyticJacobiansMatchAutomaticDifferentiation) {
  cv::RNG rng(5);
  ceres::QuaternionManifold manifold;
  for (int trial = 0; trial < 200; ++trial) {
    CameraModel camera = CameraModel::Pinhole(1200, 900, rng.uniform(400.0, 2000.0));
    camera.fy = camera.fx * rng.uniform(0.98, 1.02);
    camera.distortion = {rng.uniform(-0.3, 0.3),
                         rng.uniform(-0.1, 0.1),
                         rng.uniform(-0.01, 0.01),
                         rng.uniform(-0.01, 0.01),
                         rng.uniform(-0.05, 0.05)};
    const ReprojectionTerms terms(Eigen::Vector2d(rng.uniform(0.0, 1200.0), rng.uniform(0.0, 900.0)), camera);
    const Eigen::Quaterniond rotation =
        Eigen::Quaterniond(
            rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0))
            .normalized();
    double q[4] = {rotation.w(), rotation.x(), rotation.y(), rotation.z()};
    double centre[3] = {rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0)};
    // A point in front of the camera, within its field of view.
    const Eigen::Vector3d in_camera(rng.uniform(-0.5, 0.5), rng.uniform(-0.4, 0.4), 1.0);
    const Eigen::Vector3d world = rotation.inverse() * (in_camera * rng.uniform(0.5, 20.0)) + Eigen::Vector3d(centre);
    double point[3] = {world.x(), world.y(), world.z()};
    double intrinsics[kIntrinsicsSize] = {
        camera.fx, camera.cx + rng.uniform(-5.0, 5.0), camera.cy, camera.distortion[0], camera.distortion[1]};
    const double* parameters[4] = {q, centre, intrinsics, point};

    const ceres::AutoDiffCostFunction<ReprojectionCost, 2, 4, 3, kIntrinsicsSize, 3> automatic(
        new ReprojectionCost(terms));
    const AnalyticReprojectionCost analytic(terms);
    const Evaluation expected = Evaluate(automatic, parameters);
    const Evaluation actual = Evaluate(analytic, parameters);

    const auto near = [](const Jacobian& a, const Jacobian& b) {
      return (a - b).norm() <= 1e-9 * std::max(1.0, b.norm());
    };
    EXPECT_LE((actual.residual - expected.residual).norm(), 1e-9) << "trial " << trial;
    EXPECT_TRUE(near(actual.centre, expected.centre)) << "trial " << trial;
    EXPECT_TRUE(near(actual.intrinsics, expected.intrinsics)) << "trial " << trial;
    EXPECT_TRUE(near(actual.point, expected.point)) << "trial " << trial;
    Eigen::Matrix<double, 4, 3, Eigen::RowMajor> tangent;
    ASSERT_TRUE(manifold.PlusJacobian(q, tangent.data()));
    const Jacobian actual_tangent = actual.rotation * tangent, expected_tangent = expected.rotation * tangent;
    EXPECT_TRUE(near(actual_tangent, expected_tangent)) << "trial " << trial << "\nanalytic\n"
                                                        << actual_tangent << "\nautomatic\n"
                                                        << expected_tangent;
  }
}

}  // namespace
}  // namespace px::calib
