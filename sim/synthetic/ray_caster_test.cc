#include "sim/synthetic/ray_caster.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <opencv2/imgcodecs.hpp>

#include "sim/synthetic/scene_json.h"
#include "sim/synthetic/sim_test_util.h"

namespace px::sim {
namespace {

Scene MustParse(const std::string& text, const std::filesystem::path& base_dir = ".") {
  StatusOr<Scene> scene = ParseScene(text, base_dir, "test scene");
  EXPECT_TRUE(scene.ok()) << scene.status().ToString();
  return scene.ok() ? *scene : Scene();
}

bool BitIdentical(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size() || a.type() != b.type()) return false;
  for (int y = 0; y < a.rows; ++y) {
    if (std::memcmp(a.ptr(y), b.ptr(y), a.cols * a.elemSize()) != 0) return false;
  }
  return true;
}

constexpr char kWallAt2m[] = R"({
  "materials": {"grey": {"type": "flat", "rgb": [128, 128, 128]}},
  "objects": [{"type": "plane", "centre_m": [0, 0, 2], "normal": [0, 0, -1], "width_m": 20, "height_m": 20,
               "material": "grey"}]
})";

TEST(RayCasterTest, FrontoParallelPlaneHasConstantDepth) {
  const Scene scene = MustParse(kWallAt2m);
  CameraModel pinhole = CameraModel::Pinhole(160, 120, 140);
  CameraModel distorted = pinhole;
  distorted.distortion = {-0.15, 0.04, 0.001, -0.0005, 0};
  for (const CameraModel& camera : {pinhole, distorted}) {
    auto view = RenderView(scene, camera, Rigid3());
    ASSERT_TRUE(view.ok()) << view.status().ToString();
    double min_depth, max_depth;
    cv::minMaxLoc(view->depth_m, &min_depth, &max_depth);
    // t = (n.(c - o)) / (n.d) with d at unit depth: exactly 2 up to float rounding of the output.
    EXPECT_NEAR(min_depth, 2.0, 1e-6);
    EXPECT_NEAR(max_depth, 2.0, 1e-6);
  }
}

TEST(RayCasterTest, DepthIsAlongTheCameraAxisForAnyPose) {
  // A plane 2 m ahead of a turned, shifted camera, parallel to its image plane.
  const Rigid3 cam_from_world =
      Rigid3::LookAt(Eigen::Vector3d(0.3, -0.2, 0.1), Eigen::Vector3d(1.0, 0.1, 2.0), Eigen::Vector3d(0, -1, 0));
  const Rigid3 world_from_cam = cam_from_world.Inverse();
  const Eigen::Vector3d centre = world_from_cam * Eigen::Vector3d(0, 0, 2);
  const Eigen::Vector3d normal = world_from_cam.rotation * Eigen::Vector3d(0, 0, -1);
  const std::string text = R"({"materials": {"g": {"type": "flat", "rgb": [90, 90, 90]}},
    "objects": [{"type": "plane", "centre_m": [)" +
                           std::to_string(centre.x()) + "," + std::to_string(centre.y()) + "," +
                           std::to_string(centre.z()) + R"(], "normal": [)" + std::to_string(normal.x()) + "," +
                           std::to_string(normal.y()) + "," + std::to_string(normal.z()) +
                           R"(], "width_m": 30, "height_m": 30, "material": "g"}]})";
  const Scene scene = MustParse(text);
  auto view = RenderView(scene, CameraModel::Pinhole(120, 90, 100), cam_from_world);
  ASSERT_TRUE(view.ok());
  double min_depth, max_depth;
  cv::minMaxLoc(view->depth_m, &min_depth, &max_depth);
  // std::to_string keeps 6 decimals: the plane is placed to within 1e-6 m.
  EXPECT_NEAR(min_depth, 2.0, 1e-5);
  EXPECT_NEAR(max_depth, 2.0, 1e-5);
}

TEST(RayCasterTest, SphereSilhouetteMatchesTheAnalyticRadius) {
  constexpr double kRadius = 0.5, kDistance = 3.0, kFocal = 560;
  const Scene scene = MustParse(R"({"materials": {"w": {"type": "flat", "rgb": [200, 200, 200]}},
      "objects": [{"type": "sphere", "centre_m": [0, 0, 3], "radius_m": 0.5, "material": "w"}]})");
  auto view = RenderView(scene, CameraModel::Pinhole(640, 480, kFocal), Rigid3());
  ASSERT_TRUE(view.ok());
  // The silhouette cone has half-angle asin(R/D): its image is a circle of f tan(asin(R/D)).
  const double expected_px = kFocal * kRadius / std::sqrt(kDistance * kDistance - kRadius * kRadius);
  const int covered = cv::countNonZero(view->depth_m > 0);
  // Counting pixel centres inside a circle of radius ~95 px estimates its area to a few tens
  // of pixels, i.e. its radius to ~0.05 px; 0.25 px leaves room and still catches a 0.3% error.
  EXPECT_NEAR(std::sqrt(covered / M_PI), expected_px, 0.25);
  // The nearest point is on the axis, at D - R; the principal point (319.5, 239.5) lies between
  // four pixels, whose centre rays are 0.7 px off-axis: depth differs by < 1e-5 m there.
  EXPECT_NEAR(view->depth_m.at<float>(240, 320), kDistance - kRadius, 1e-4);
  // Along the middle row, the covered span is the diameter (to within one pixel).
  const cv::Mat row = view->depth_m.row(240) > 0;
  EXPECT_NEAR(cv::countNonZero(row), 2 * expected_px, 1.0);
  // Nothing else is drawn: outside, depth 0 and the background colour.
  EXPECT_EQ(view->depth_m.at<float>(0, 0), 0.0f);
  EXPECT_EQ(view->bgr.at<cv::Vec3b>(0, 0), cv::Vec3b(0, 0, 0));
}

// A sensor pixel on a silhouette records the fraction of it the object covers. Pixels whose
// 2x2 rays disagree, or whose neighbours' centres see another surface (an edge can cross a
// pixel between its rays), are integrated over 8x8 rays: each pixel's colour is its coverage of
// the sphere's analytic disc, found here by 256x256 point tests.
TEST(RayCasterTest, SilhouettePixelsRecordTheirCoverage) {
  constexpr double kRadius = 0.5, kDistance = 3.0, kFocal = 560;
  const Scene scene = MustParse(R"({"materials": {"w": {"type": "flat", "rgb": [255, 255, 255], "lit": false}},
      "objects": [{"type": "sphere", "centre_m": [0, 0, 3], "radius_m": 0.5, "material": "w"}]})");
  const CameraModel camera = CameraModel::Pinhole(640, 480, kFocal);
  auto view = RenderView(scene, camera, Rigid3());
  ASSERT_TRUE(view.ok());
  const double disc_px = kFocal * kRadius / std::sqrt(kDistance * kDistance - kRadius * kRadius);
  double sum_error = 0, max_error = 0;
  int edge_pixels = 0;
  for (int y = 0; y < camera.height; ++y) {
    for (int x = 0; x < camera.width; ++x) {
      const double r = std::hypot(x - camera.cx, y - camera.cy);
      if (std::abs(r - disc_px) > 1.5) continue;
      constexpr int kSteps = 256;
      int inside = 0;
      for (int j = 0; j < kSteps; ++j) {
        for (int i = 0; i < kSteps; ++i) {
          const double px = x - 0.5 + (i + 0.5) / kSteps, py = y - 0.5 + (j + 0.5) / kSteps;
          inside += std::hypot(px - camera.cx, py - camera.cy) < disc_px;
        }
      }
      const double coverage = static_cast<double>(inside) / (kSteps * kSteps);
      if (coverage <= 0 || coverage >= 1) continue;
      const double error = std::abs(view->bgr.at<cv::Vec3b>(y, x)[1] - 255 * coverage);
      sum_error += error;
      max_error = std::max(max_error, error);
      ++edge_pixels;
    }
  }
  ASSERT_GT(edge_pixels, 500);
  std::printf("%d silhouette pixels: coverage error mean %.2f, max %.1f levels\n",
              edge_pixels,
              sum_error / edge_pixels,
              max_error);
  // Measured: mean 1.71, max 10.5 levels (8x8 rays: steps of 4). The 2x2 rays alone (steps of
  // 64, and pixels missed where the edge passes between the rays) gave mean 18.2, max 58.0.
  EXPECT_LT(sum_error / edge_pixels, 4.0);
  EXPECT_LT(max_error, 24.0);
}

TEST(RayCasterTest, TextureAppearsUprightAndUnmirroredAtOneTexelPerPixel) {
  testing::TempDir dir;
  cv::Mat texture(48, 64, CV_8UC3);
  cv::RNG rng(7);
  rng.fill(texture, cv::RNG::UNIFORM, 0, 256);
  ASSERT_TRUE(cv::imwrite((dir.path() / "noise.png").string(), texture));
  // A camera with f = 100 px sees a 0.64 x 0.48 m card at 1 m as exactly 64 x 48 pixels.
  const Scene scene = MustParse(R"({"materials": {"t": {"type": "texture", "file": "noise.png", "lit": false}},
      "objects": [{"type": "plane", "centre_m": [0, 0, 1], "normal": [0, 0, -1], "up": [0, -1, 0],
                   "width_m": 0.64, "height_m": 0.48, "material": "t"}]})",
                                dir.path());
  RenderOptions options;
  options.supersampling = 1;
  auto view = RenderView(scene, CameraModel::Pinhole(64, 48, 100), Rigid3(), options);
  ASSERT_TRUE(view.ok());
  // Each pixel centre lands on a texel centre, at mip level 0: the render is the image (one
  // level of rounding slack for the float path).
  cv::Mat diff;
  cv::absdiff(view->bgr, texture, diff);
  double max_diff;
  cv::minMaxLoc(diff.reshape(1), nullptr, &max_diff);
  EXPECT_LE(max_diff, 1.0);
}

TEST(RayCasterTest, DistantFineTexturesAverageInsteadOfAliasing) {
  testing::TempDir dir;
  // A one-texel black/white checker image and a 1 cm procedural checker, both seen from so far
  // that one pixel covers ~16 texels or ~10 squares: without filtering they would alias into
  // coarse stripes or noise; filtered, they are a flat mid grey.
  cv::Mat fine(256, 256, CV_8UC3);
  for (int y = 0; y < fine.rows; ++y) {
    for (int x = 0; x < fine.cols; ++x) fine.at<cv::Vec3b>(y, x) = cv::Vec3b::all(((x + y) % 2) ? 255 : 0);
  }
  ASSERT_TRUE(cv::imwrite((dir.path() / "fine.png").string(), fine));
  const Scene scene = MustParse(R"({"materials": {
        "image": {"type": "texture", "file": "fine.png", "lit": false},
        "procedural": {"type": "checker", "rgb_a": [0, 0, 0], "rgb_b": [255, 255, 255], "square_m": 0.01}},
      "objects": [
        {"type": "plane", "centre_m": [-2.5, 0, 10], "normal": [0, 0, -1], "width_m": 4, "height_m": 4, "material": "image"},
        {"type": "plane", "centre_m": [2.5, 0, 10], "normal": [0, 0, -1], "width_m": 4, "height_m": 4, "material": {
          "type": "checker", "rgb_a": [0, 0, 0], "rgb_b": [255, 255, 255], "square_m": 0.01, "lit": false}}]})",
                                dir.path());
  auto view = RenderView(scene, CameraModel::Pinhole(200, 100, 100), Rigid3());
  ASSERT_TRUE(view.ok());
  // Each card spans 40x40 px (4 m at 10 m, f = 100), centred 25 px left and right of the middle.
  for (const cv::Rect& rect : {cv::Rect(60, 35, 30, 30), cv::Rect(110, 35, 30, 30)}) {
    cv::Scalar mean, stddev;
    cv::meanStdDev(view->bgr(rect), mean, stddev);
    EXPECT_NEAR(mean[0], 127.5, 8.0) << rect;
    // Aliasing would give a spread of tens of levels; a filtered average stays within a few.
    EXPECT_LT(stddev[0], 4.0) << rect;
  }
}

TEST(RayCasterTest, OutputIsBitIdenticalForAnyThreadCount) {
  auto scene = LoadScene(testing::SceneFile("still_life"));
  ASSERT_TRUE(scene.ok()) << scene.status().ToString();
  CameraModel camera = CameraModel::Pinhole(200, 150, 175);
  camera.distortion = {-0.1, 0.02, 0, 0, 0};
  const Rigid3 pose(Eigen::Quaterniond(Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitY())),
                    Eigen::Vector3d(0.02, -0.01, 0));
  const int threads_before = cv::getNumThreads();
  std::vector<RenderedView> views;
  // At most 2: OpenCV's TBB back end ignores requests beyond the machine's cores (CI has 2).
  for (int threads : {2, 1}) {
    cv::setNumThreads(threads);
    auto view = RenderView(*scene, camera, pose);
    ASSERT_TRUE(view.ok());
    views.push_back(*view);
  }
  cv::setNumThreads(threads_before);
  for (size_t i = 1; i < views.size(); ++i) {
    EXPECT_TRUE(BitIdentical(views[0].bgr, views[i].bgr));
    EXPECT_TRUE(BitIdentical(views[0].depth_m, views[i].depth_m));
  }
}

TEST(RayCasterTest, RejectsBadOptionsAndCameras) {
  const Scene scene = MustParse(kWallAt2m);
  RenderOptions options;
  options.supersampling = 9;
  EXPECT_EQ(RenderView(scene, CameraModel::Pinhole(10, 10, 10), Rigid3(), options).status().code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(RenderView(scene, CameraModel::Pinhole(0, 10, 10), Rigid3()).status().code(), StatusCode::kInvalidArgument);
}

TEST(RayCasterTest, NearerObjectsOccludeFartherOnes) {
  // A box in front of a sphere in front of a wall: along the axis the box wins.
  const Scene scene = MustParse(R"({"materials": {"g": {"type": "flat", "rgb": [100, 100, 100]}},
      "objects": [
        {"type": "plane", "centre_m": [0, 0, 5], "normal": [0, 0, -1], "width_m": 20, "height_m": 20, "material": "g"},
        {"type": "sphere", "centre_m": [0, 0, 3], "radius_m": 0.5, "material": "g"},
        {"type": "box", "centre_m": [0, 0, 1.5], "size_m": [0.2, 0.2, 0.4], "rotation_deg": [0, 0, 30], "material": "g"}]})");
  auto view = RenderView(scene, CameraModel::Pinhole(101, 101, 100), Rigid3());
  ASSERT_TRUE(view.ok());
  EXPECT_NEAR(view->depth_m.at<float>(50, 50), 1.3, 1e-6);  // box front face at 1.5 - 0.2
  // 12 px right of the axis the ray passes the box (its rotated half-width is at most 0.137 m,
  // the ray is 0.156 m off-axis at 1.3 m) and meets the sphere at t = 2.61 m; 45 px right it
  // clears the sphere's silhouette (16.9 px) and meets the wall.
  EXPECT_NEAR(view->depth_m.at<float>(50, 62), 2.61, 0.01);
  EXPECT_NEAR(view->depth_m.at<float>(50, 95), 5.0, 1e-5);
}

}  // namespace
}  // namespace px::sim
