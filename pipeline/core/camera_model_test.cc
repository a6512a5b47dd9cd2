#include "pipeline/core/camera_model.h"

#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>

namespace px {
namespace {

CameraModel DistortedCamera() {
  CameraModel c = CameraModel::Pinhole(640, 480, 500);
  c.distortion = {-0.12, 0.03, 0.001, -0.0015, 0.0};
  return c;
}

TEST(CameraModelTest, ProjectUnprojectRoundTrip) {
  const CameraModel camera = DistortedCamera();
  for (double x : {-0.4, 0.0, 0.3}) {
    for (double y : {-0.3, 0.1, 0.35}) {
      Eigen::Vector3d p(x * 2.5, y * 2.5, 2.5);
      Eigen::Vector2d pixel;
      ASSERT_TRUE(camera.Project(p, &pixel));
      Eigen::Vector3d ray = camera.Unproject(pixel);
      EXPECT_NEAR(ray.x() * 2.5, p.x(), 1e-8);
      EXPECT_NEAR(ray.y() * 2.5, p.y(), 1e-8);
    }
  }
}

TEST(CameraModelTest, MatchesOpenCvProjectPoints) {
  const CameraModel camera = DistortedCamera();
  std::vector<cv::Point3d> points = {{0.2, -0.1, 1.5}, {-0.5, 0.4, 2.0}, {0.0, 0.0, 1.0}};
  std::vector<cv::Point2d> expected;
  cv::projectPoints(
      points, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), cv::Mat(camera.CvK()), camera.CvDistortion(), expected);
  for (size_t i = 0; i < points.size(); ++i) {
    Eigen::Vector2d pixel;
    ASSERT_TRUE(camera.Project({points[i].x, points[i].y, points[i].z}, &pixel));
    EXPECT_NEAR(pixel.x(), expected[i].x, 1e-9);
    EXPECT_NEAR(pixel.y(), expected[i].y, 1e-9);
  }
}

TEST(CameraModelTest, BehindTheCameraDoesNotProject) {
  Eigen::Vector2d pixel;
  EXPECT_FALSE(CameraModel::Pinhole(64, 48, 50).Project({0, 0, -1}, &pixel));
}

TEST(CameraModelTest, ValidateNamesTheProblem) {
  CameraModel c = CameraModel::Pinhole(640, 480, 500);
  EXPECT_TRUE(c.Validate().ok());
  c.fx = -1;
  EXPECT_NE(c.Validate().message().find("focal length"), std::string::npos);
  c = CameraModel::Pinhole(640, 480, 500);
  c.cx = 900;
  EXPECT_NE(c.Validate().message().find("principal point"), std::string::npos);
}

TEST(CameraModelTest, ScaledKeepsPixelCentres) {
  CameraModel c = CameraModel::Pinhole(640, 480, 500);
  CameraModel half = c.Scaled(0.5);
  EXPECT_EQ(half.width, 320);
  EXPECT_DOUBLE_EQ(half.fx, 250);
  // A ray through the full image's centre passes through the half image's centre.
  EXPECT_DOUBLE_EQ(half.cx, 159.5);
}

}  // namespace
}  // namespace px
