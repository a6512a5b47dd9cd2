#include "pipeline/calib/make_views.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

namespace px {
namespace {

constexpr double kBlobSigmaPx = 2.0;
constexpr int kGridSpacingPx = 40;

// A lens with clear barrel distortion: points near the corners move by several pixels.
CameraModel DistortedCamera() {
  CameraModel camera = CameraModel::Pinhole(640, 480, 500.0);
  camera.cx = 322.5;  // off-centre, so a wrong principal point would show
  camera.cy = 237.0;
  camera.distortion = {-0.25, 0.08, 0.001, -0.0015, 0.0};
  return camera;
}

// Grid points where the pinhole (undistorted) camera sees a blob.
std::vector<cv::Point2d> PinholeGrid(const CameraModel& camera) {
  std::vector<cv::Point2d> grid;
  for (int y = kGridSpacingPx / 2; y < camera.height; y += kGridSpacingPx) {
    for (int x = kGridSpacingPx / 2; x < camera.width; x += kGridSpacingPx) grid.emplace_back(x, y);
  }
  return grid;
}

// Renders what the distorted lens sees of a scene that a pinhole camera with the same K would
// image as Gaussian blobs on `grid`: each distorted pixel is traced back to its undistorted ray
// with CameraModel::Unproject (independent of OpenCV's undistortion maps under test).
cv::Mat RenderDistortedBlobs(const CameraModel& camera) {
  cv::Mat image(camera.height, camera.width, CV_8UC3);
  for (int y = 0; y < camera.height; ++y) {
    for (int x = 0; x < camera.width; ++x) {
      const Eigen::Vector3d ray = camera.Unproject(Eigen::Vector2d(x, y));
      const double u = camera.fx * ray.x() + camera.cx;
      const double v = camera.fy * ray.y() + camera.cy;
      // The nearest grid blob dominates; its neighbours are > 9 sigma away.
      const double gx = std::round((u - kGridSpacingPx / 2.0) / kGridSpacingPx) * kGridSpacingPx + kGridSpacingPx / 2.0;
      const double gy = std::round((v - kGridSpacingPx / 2.0) / kGridSpacingPx) * kGridSpacingPx + kGridSpacingPx / 2.0;
      const double r2 = (u - gx) * (u - gx) + (v - gy) * (v - gy);
      const auto value = cv::saturate_cast<uchar>(10.0 + 240.0 * std::exp(-r2 / (2 * kBlobSigmaPx * kBlobSigmaPx)));
      image.at<cv::Vec3b>(y, x) = cv::Vec3b(value, value, value);
    }
  }
  return image;
}

// Intensity-weighted centroid (above the background level) in a window around `guess`.
cv::Point2d BlobCentroid(const cv::Mat& image, cv::Point2d guess, int radius) {
  double sum = 0, sx = 0, sy = 0;
  const int cx = static_cast<int>(std::lround(guess.x)), cy = static_cast<int>(std::lround(guess.y));
  for (int y = cy - radius; y <= cy + radius; ++y) {
    for (int x = cx - radius; x <= cx + radius; ++x) {
      if (x < 0 || y < 0 || x >= image.cols || y >= image.rows) continue;
      const double w = std::max(0.0, image.at<cv::Vec3b>(y, x)[1] - 10.0);
      sum += w;
      sx += w * x;
      sy += w * y;
    }
  }
  return sum > 0 ? cv::Point2d(sx / sum, sy / sum) : guess;
}

RigCalibration OneLensRig(const CameraModel& camera) {
  RigCalibration rig;
  rig.rig_name = "test-rig";
  rig.lattice = LatticeLayout::Regular(1, 1, camera.width, camera.height, 0);
  rig.lenses = {{camera, Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.0125, -0.0125, 0))}};
  return rig;
}

TEST(MakeViewsTest, UndistortionMovesPointsToThePinholeProjection) {
  const CameraModel camera = DistortedCamera();
  const cv::Mat distorted = RenderDistortedBlobs(camera);
  const std::vector<cv::Point2d> grid = PinholeGrid(camera);

  // The distortion must matter: in the raw tile, blobs near the corners sit pixels away from
  // their pinhole positions (otherwise this test could not tell undistortion from a copy).
  double max_raw_offset = 0;
  for (const cv::Point2d& g : grid) {
    Eigen::Vector2d distorted_px;
    ASSERT_TRUE(camera.Project(camera.WithoutDistortion().Unproject(Eigen::Vector2d(g.x, g.y)), &distorted_px));
    max_raw_offset = std::max(max_raw_offset, std::hypot(distorted_px.x() - g.x, distorted_px.y() - g.y));
  }
  ASSERT_GT(max_raw_offset, 10.0);

  UndistortCache cache;
  StatusOr<std::vector<View>> views = MakeViews({distorted}, OneLensRig(camera), CalibOptions(), &cache);
  ASSERT_TRUE(views.ok()) << views.status().ToString();
  ASSERT_EQ(views->size(), 1u);
  const View& view = (*views)[0];
  EXPECT_FALSE(view.camera.HasDistortion());
  EXPECT_EQ(view.camera.fx, camera.fx);
  EXPECT_EQ(view.camera.cx, camera.cx);
  EXPECT_EQ(view.image.size(), distorted.size());

  // Every blob whose window lies inside the image must come back to its pinhole position. The
  // remaining error is bilinear resampling (OpenCV's remap uses 1/32 px weights) and 8-bit
  // quantisation of the blobs: a few hundredths of a pixel, so 0.1 px max is a safe bound.
  double max_error = 0, sum_error = 0;
  int count = 0;
  for (const cv::Point2d& g : grid) {
    if (g.x < 8 || g.y < 8 || g.x > camera.width - 9 || g.y > camera.height - 9) continue;
    const cv::Point2d c = BlobCentroid(view.image, g, 7);
    const double error = std::hypot(c.x - g.x, c.y - g.y);
    max_error = std::max(max_error, error);
    sum_error += error;
    ++count;
  }
  std::printf("undistortion: %d blobs, max error %.4f px, mean %.4f px (raw offset up to %.1f px)\n",
              count,
              max_error,
              sum_error / count,
              max_raw_offset);
  ASSERT_GT(count, 150);
  EXPECT_LT(max_error, 0.1);
  EXPECT_LT(sum_error / count, 0.04);
}

TEST(MakeViewsTest, PoseIsCamFromRigAndPinholeTilesAreCopiedUnchanged) {
  RigCalibration rig;
  rig.rig_name = "pop9";
  rig.lattice = LatticeLayout::Regular(3, 3, 64, 48, 2);
  std::vector<cv::Mat> tiles;
  cv::RNG rng(7);
  for (int i = 0; i < 9; ++i) {
    const Eigen::Vector3d t(-0.025 * (i % 3 - 1), -0.025 * (i / 3 - 1), 0.001 * i);
    rig.lenses.push_back({CameraModel::Pinhole(64, 48, 60.0), Rigid3(Eigen::Quaterniond::Identity(), t)});
    cv::Mat tile(48, 64, CV_8UC3);
    rng.fill(tile, cv::RNG::UNIFORM, 0, 256);
    tiles.push_back(tile);
  }
  StatusOr<std::vector<View>> views = MakeViews(tiles, rig, CalibOptions());
  ASSERT_TRUE(views.ok()) << views.status().ToString();
  ASSERT_EQ(views->size(), 9u);
  for (int i = 0; i < 9; ++i) {
    const View& view = (*views)[i];
    EXPECT_EQ(view.id.value, i);
    EXPECT_EQ(cv::norm(view.image, tiles[i], cv::NORM_INF), 0.0);
    EXPECT_NE(view.image.data, tiles[i].data) << "views must own their pixels";
    EXPECT_TRUE(view.cam_from_world.translation.isApprox(rig.lenses[i].cam_from_rig.translation));
    EXPECT_TRUE(view.cam_from_world.rotation.isApprox(rig.lenses[i].cam_from_rig.rotation));
  }
}

TEST(MakeViewsTest, CacheSharesMapsBetweenIdenticalLenses) {
  RigCalibration rig;
  rig.rig_name = "pop4";
  rig.lattice = LatticeLayout::Regular(2, 2, 80, 60, 0);
  CameraModel camera = CameraModel::Pinhole(80, 60, 70.0);
  camera.distortion = {-0.1, 0, 0, 0, 0};
  for (int i = 0; i < 4; ++i) rig.lenses.push_back({camera, Rigid3()});
  rig.lenses[3].camera.fx = 71.0;  // one lens differs
  const std::vector<cv::Mat> tiles(4, cv::Mat(60, 80, CV_8UC3, cv::Scalar(1, 2, 3)));
  UndistortCache cache;
  ASSERT_TRUE(MakeViews(tiles, rig, CalibOptions(), &cache).ok());
  EXPECT_EQ(cache.NumCached(), 2);
  ASSERT_TRUE(MakeViews(tiles, rig, CalibOptions(), &cache).ok());  // the next shot
  EXPECT_EQ(cache.NumCached(), 2);
}

TEST(MakeViewsTest, WrongTileSizeIsAnErrorNamingTheView) {
  RigCalibration rig;
  rig.rig_name = "pop4";
  rig.lattice = LatticeLayout::Regular(2, 2, 80, 60, 0);
  for (int i = 0; i < 4; ++i) rig.lenses.push_back({CameraModel::Pinhole(80, 60, 70.0), Rigid3()});
  std::vector<cv::Mat> tiles(4, cv::Mat(60, 80, CV_8UC3, cv::Scalar(0, 0, 0)));
  tiles[2] = cv::Mat(60, 79, CV_8UC3, cv::Scalar(0, 0, 0));
  StatusOr<std::vector<View>> views = MakeViews(tiles, rig, CalibOptions());
  ASSERT_FALSE(views.ok());
  EXPECT_EQ(views.status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(views.status().message(), "view 2: image is 79x60, lens intrinsics are for 80x60");

  tiles[2] = cv::Mat(60, 80, CV_8UC1, cv::Scalar(0));
  views = MakeViews(tiles, rig, CalibOptions());
  ASSERT_FALSE(views.ok());
  EXPECT_NE(views.status().message().find("view 2"), std::string::npos) << views.status().message();

  tiles.pop_back();
  views = MakeViews(tiles, rig, CalibOptions());
  ASSERT_FALSE(views.ok());
  EXPECT_EQ(views.status().message(), "got 3 tiles, rig 'pop4' calibrates 4 lenses");
}

TEST(MakeViewsTest, InvalidOptionsAreRejected) {
  CalibOptions options;
  options.interpolation = static_cast<CalibOptions::Interpolation>(7);
  EXPECT_FALSE(options.Validate().ok());
  const cv::Mat image(10, 10, CV_8UC3, cv::Scalar(0, 0, 0));
  EXPECT_FALSE(MakeView(ViewId{0}, image, CameraModel::Pinhole(10, 10, 10), Rigid3(), options).ok());
}

}  // namespace
}  // namespace px
