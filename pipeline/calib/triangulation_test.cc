#include "pipeline/calib/triangulation.h"

#include <gtest/gtest.h>

#include "pipeline/calib/geometry_test_util.h"

namespace px::calib {
namespace {

TEST(TriangulationTest, ExactRaysGiveTheExactPoint) {
  const std::vector<Rigid3> cams = {Rigid3(),
                                    Rigid3(testing::SmallRotation(0, 2, 0), Eigen::Vector3d(-0.1, 0, 0)),
                                    Rigid3(testing::SmallRotation(1, 0, 0), Eigen::Vector3d(0, -0.1, 0.02))};
  const Eigen::Vector3d point(0.3, -0.2, 2.5);
  std::vector<Eigen::Vector3d> rays;
  for (const Rigid3& cam : cams) rays.push_back(cam * point);
  const std::optional<Eigen::Vector3d> triangulated = TriangulatePoint(cams, rays);
  ASSERT_TRUE(triangulated.has_value());
  EXPECT_LT((*triangulated - point).norm(), 1e-9);
  // Centres about 0.14 m apart (cameras 1 and 2) seen from 2.5 m: about 3.3 degrees.
  EXPECT_NEAR(MaxTriangulationAngleDeg(point, cams), 3.2, 0.3);
}

TEST(TriangulationTest, FewerThanTwoViewsOrRaysBehindGiveNothing) {
  EXPECT_FALSE(TriangulatePoint({Rigid3()}, {Eigen::Vector3d(0, 0, 1)}).has_value());
  EXPECT_FALSE(
      TriangulatePoint({Rigid3(), Rigid3()}, {Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0, 0, -1)}).has_value());
}

}  // namespace
}  // namespace px::calib
