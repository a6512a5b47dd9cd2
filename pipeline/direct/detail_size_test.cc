#include "pipeline/direct/detail_size.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

namespace px::direct {
namespace {

VirtualCamera OutputCamera() {
  VirtualCamera camera;
  camera.camera = CameraModel::Pinhole(1080, 1920, 1700);
  camera.camera.cx = 530.25;  // off centre, as a framed crop's principal point is
  camera.camera.cy = 961.5;
  return camera;
}

TEST(DetailSizeTest, SmallEnlargementsAreDrawnAtTheOutputSize) {
  const VirtualCamera camera = OutputCamera();
  const VirtualCamera same = CameraAtDetail(camera, kDrawAtDetailAbove);
  EXPECT_EQ(same.camera.width, 1080);
  EXPECT_EQ(same.camera.fx, camera.camera.fx);
  const cv::Mat frame(1920, 1080, CV_8UC3, cv::Scalar(1, 2, 3));
  EXPECT_EQ(EnlargeToOutput(frame, 1080, 1920).data, frame.data) << "a frame of the output's size is not resampled";
}

// A point's pixel in the small camera, enlarged as cv::resize enlarges, lands on its pixel in
// the output camera: the two cameras agree to a hundredth of a pixel.
TEST(DetailSizeTest, TheSmallCameraSeesWhatTheEnlargementShows) {
  const VirtualCamera camera = OutputCamera();
  const VirtualCamera small = CameraAtDetail(camera, 2.13);
  EXPECT_EQ(small.camera.width, 507);
  EXPECT_EQ(small.camera.height, 901);
  const double sx = 1080.0 / small.camera.width, sy = 1920.0 / small.camera.height;
  for (const Eigen::Vector3d& point : {Eigen::Vector3d(0.1, -0.3, 1.2), Eigen::Vector3d(-0.2, 0.25, 0.8)}) {
    Eigen::Vector2d in_output, in_small;
    ASSERT_TRUE(camera.camera.Project(point, &in_output));
    ASSERT_TRUE(small.camera.Project(point, &in_small));
    EXPECT_NEAR((in_small.x() + 0.5) * sx - 0.5, in_output.x(), 1e-2);
    EXPECT_NEAR((in_small.y() + 0.5) * sy - 0.5, in_output.y(), 1e-2);
  }

  // A dot drawn in the small frame is enlarged onto the output pixel the output camera projects
  // it to.
  const Eigen::Vector3d dot(0.05, -0.1, 1.0);
  Eigen::Vector2d in_small, in_output;
  ASSERT_TRUE(small.camera.Project(dot, &in_small));
  ASSERT_TRUE(camera.camera.Project(dot, &in_output));
  cv::Mat drawn(small.camera.height, small.camera.width, CV_8UC3, cv::Scalar::all(0));
  cv::circle(drawn,
             cv::Point(static_cast<int>(std::lround(in_small.x())), static_cast<int>(std::lround(in_small.y()))),
             0,
             cv::Scalar::all(255),
             cv::FILLED);
  const cv::Mat large = EnlargeToOutput(drawn, 1080, 1920);
  ASSERT_EQ(large.size(), cv::Size(1080, 1920));
  cv::Mat grey;
  cv::cvtColor(large, grey, cv::COLOR_BGR2GRAY);
  cv::Point brightest;
  cv::minMaxLoc(grey, nullptr, nullptr, nullptr, &brightest);
  EXPECT_NEAR(brightest.x, in_output.x(), 2.5);
  EXPECT_NEAR(brightest.y, in_output.y(), 2.5);
}

}  // namespace
}  // namespace px::direct
