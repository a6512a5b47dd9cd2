// The dataset loaders on the real data in ../shared/data (skipped with a message when absent):
// the geometry they report must explain the pixels and the reference reconstructions.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/imgproc.hpp>

#include "eval/datasets/hci_light_field.h"
#include "eval/datasets/llff.h"
#include "sim/synthetic/data_paths.h"

namespace px::eval {
namespace {

namespace fs = std::filesystem;

fs::path DataDir(const std::string& name) { return px::sim::SharedDataDir() / name; }

#define SKIP_WITHOUT(dir)                                           \
  if (!fs::exists(dir))                                             \
  GTEST_SKIP() << (dir).string()                                    \
               << " is absent (the shared datasets sit beside the " \
                  "repository as ../shared/data; set PX_DATA_DIR)"

// Mean absolute grey difference between a and b over the interior.
double MeanAbsDiff(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat ga, gb, diff;
  cv::cvtColor(a, ga, cv::COLOR_BGR2GRAY);
  cv::cvtColor(b, gb, cv::COLOR_BGR2GRAY);
  cv::absdiff(ga, gb, diff);
  const cv::Rect interior(16, 16, a.cols - 32, a.rows - 32);
  return cv::mean(diff(interior))[0];
}

TEST(HciLightField, GeometryExplainsThePixels) {
  const fs::path dir = DataDir("hci_4dlf_antinous");
  SKIP_WITHOUT(dir);
  StatusOr<HciLightField> lf = LoadHciLightField(dir);
  ASSERT_TRUE(lf.ok()) << lf.status().ToString();
  ASSERT_EQ(lf->views.size(), 81u);
  EXPECT_NEAR(lf->offset_px, 20.898, 0.01);  // parameters.cfg's own `offset`
  ASSERT_FALSE(lf->gt_disparity.empty());
  const View& centre = lf->views[lf->CentreIndex()];

  // Warp the view two steps right and one down into the centre view through each view's camera,
  // pose and the ground-truth depth: it must match far better than the raw view does, and far
  // better than the mirrored grid (camera (r, c) at -(c - 4, r - 4) B with principal points
  // shifted the other way), which would explain the pixels only if positive disparity meant far.
  const cv::Mat depth = lf->GtDepth();
  for (int index : {lf->CentreIndex() + 2, lf->CentreIndex() + lf->cols - 1}) {
    const View& loaded = lf->views[index];
    View mirrored = loaded;
    mirrored.camera.cx = 2 * centre.camera.cx - loaded.camera.cx;
    mirrored.camera.cy = 2 * centre.camera.cy - loaded.camera.cy;
    mirrored.cam_from_world.translation = -loaded.cam_from_world.translation;
    double aligned_by[2] = {0, 0};
    for (int mirror : {0, 1}) {
      const View& other = mirror ? mirrored : loaded;
      cv::Mat map_x(depth.size(), CV_32F), map_y(depth.size(), CV_32F);
      for (int y = 0; y < depth.rows; ++y) {
        for (int x = 0; x < depth.cols; ++x) {
          const Eigen::Vector3d p_in_centre = centre.camera.Unproject({x, y}) * depth.at<float>(y, x);
          const Eigen::Vector3d p_in_world = centre.cam_from_world.Inverse() * p_in_centre;
          Eigen::Vector2d pixel;
          other.camera.Project(other.cam_from_world * p_in_world, &pixel);
          map_x.at<float>(y, x) = static_cast<float>(pixel.x());
          map_y.at<float>(y, x) = static_cast<float>(pixel.y());
        }
      }
      cv::Mat warped;
      cv::remap(other.image, warped, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
      aligned_by[mirror] = MeanAbsDiff(warped, centre.image);
    }
    const double raw = MeanAbsDiff(loaded.image, centre.image);
    const double aligned = aligned_by[0];
    std::cout << "HCI view " << index << " vs centre: " << raw << " grey levels raw, " << aligned << " warped, "
              << aligned_by[1] << " warped through the mirrored grid\n";
    EXPECT_LT(aligned, 2.5);
    EXPECT_LT(aligned, raw / 2);
    EXPECT_LT(aligned, aligned_by[1] / 2);
  }
  EXPECT_EQ(lf->CentreGrid(1).size(), 9u);
  EXPECT_EQ(lf->CentreGrid(1)[4].id.value, lf->CentreIndex());
}

// COLMAP's sparse points must lie in front of every camera, within LLFF's near/far bounds.
TEST(LlffScene, PosesPutColmapPointsBetweenTheBounds) {
  const fs::path dir = DataDir("llff_fern");
  SKIP_WITHOUT(dir);
  StatusOr<LlffScene> scene = LoadLlffScene(dir);
  ASSERT_TRUE(scene.ok()) << scene.status().ToString();
  ASSERT_EQ(scene->views.size(), 20u);
  EXPECT_EQ(scene->views[0].image.cols, 504);
  EXPECT_NEAR(scene->views[0].camera.fx, 3260.53 / 8, 0.5);

  // points3D.bin: count, then per point id, xyz, rgb, error, track.
  std::ifstream in(dir / "sparse/0/points3D.bin", std::ios::binary);
  ASSERT_TRUE(in.good());
  uint64_t count = 0;
  in.read(reinterpret_cast<char*>(&count), 8);
  std::vector<Eigen::Vector3d> points;
  for (uint64_t i = 0; i < count && in; ++i) {
    uint64_t id, track_length;
    double xyz[3], error;
    uint8_t rgb[3];
    in.read(reinterpret_cast<char*>(&id), 8);
    in.read(reinterpret_cast<char*>(xyz), 24);
    in.read(reinterpret_cast<char*>(rgb), 3);
    in.read(reinterpret_cast<char*>(&error), 8);
    in.read(reinterpret_cast<char*>(&track_length), 8);
    in.ignore(static_cast<std::streamsize>(track_length * 8));
    points.emplace_back(xyz[0], xyz[1], xyz[2]);
  }
  ASSERT_GT(points.size(), 1000u);
  for (size_t v = 0; v < scene->views.size(); v += 6) {
    const View& view = scene->views[v];
    int inside = 0, seen = 0;
    for (const Eigen::Vector3d& p : points) {
      const Eigen::Vector3d p_in_cam = view.cam_from_world * p;
      Eigen::Vector2d pixel;
      if (!view.camera.Project(p_in_cam, &pixel)) continue;
      if (pixel.x() < 0 || pixel.y() < 0 || pixel.x() >= view.camera.width || pixel.y() >= view.camera.height) continue;
      seen++;
      if (p_in_cam.z() > 0.9 * scene->near_depth[v] && p_in_cam.z() < 1.1 * scene->far_depth[v]) inside++;
    }
    EXPECT_GT(seen, static_cast<int>(points.size() * 0.6)) << "view " << v;
    EXPECT_GT(inside, seen * 0.97) << "view " << v;
  }
}

}  // namespace
}  // namespace px::eval
