#include "pipeline/render/seam_skirts.h"

#include <gtest/gtest.h>

#include <array>
#include <vector>

#include "pipeline/render/cpu_scene_renderer.h"
#include "pipeline/render/seam_test_util.h"

namespace px::render {
namespace {

const CameraModel kCamera = CameraModel::Pinhole(64, 48, 60);
constexpr int kWall = 0, kCardLeft = 1, kCardRight = 2;

// One view of a card (x in [14, 50), y in [8, 40)) in front of a wall at 3 m, the card cut into
// two segments at x = 20 whose fronto-parallel planes disagree: the left one at 1 m, the right
// one at `right_depth_m` (a plane fit's error on one surface). Hard seams, no two-layer band.
LayeredDepthView CardOverWall(double right_depth_m) {
  cv::Mat labels(kCamera.height, kCamera.width, CV_32S);
  for (int y = 0; y < kCamera.height; ++y) {
    for (int x = 0; x < kCamera.width; ++x) {
      const bool card = x >= 14 && x < 50 && y >= 8 && y < 40;
      labels.at<int32_t>(y, x) = !card ? kWall : x < 20 ? kCardLeft : kCardRight;
    }
  }
  return testing::OneLayerView(kCamera,
                               labels,
                               {cv::Vec3b(20, 20, 20), cv::Vec3b(100, 150, 200), cv::Vec3b(100, 150, 200)},
                               {{{0, 0, 1.0 / 3.0}, {0, 0, 1.0}, {0, 0, 1.0 / right_depth_m}}});
}

// The card's pixels (true depth about 0.5 m from the camera) that render the wall: the crack.
int WallPixelsInsideTheCard(const SeamSkirtOptions& skirts) {
  View pose;
  pose.id = ViewId(0);
  pose.camera = kCamera;
  RenderOptions options;
  options.seam_skirts = skirts;
  auto renderer = CpuSceneRenderer::Create({pose}, {CardOverWall(1.04)}, options);
  EXPECT_TRUE(renderer.ok()) << renderer.status().ToString();
  if (!renderer.ok()) return -1;
  // Half a metre forward: the card is magnified 2x and the seam's two sides part by about a pixel.
  VirtualCamera camera;
  camera.camera = kCamera;
  camera.cam_from_world = Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, -0.5));
  auto frame = (*renderer)->Render(camera);
  EXPECT_TRUE(frame.ok()) << frame.status().ToString();
  if (!frame.ok()) return -1;
  int wall = 0;
  for (int y = 10; y < 38; ++y) {   // rows well inside the card
    for (int x = 2; x < 20; ++x) {  // around the seam, which lands near x = 8
      if (frame->depth_m.at<float>(y, x) > 0.6f) ++wall;
    }
  }
  return wall;
}

TEST(SeamSkirtsTest, ASeamBetweenTwoPlanesOfOneSurfaceDoesNotCrackInAMagnifiedView) {
  SeamSkirtOptions off;
  off.max_step = 0;
  SeamSkirtOptions full;
  full.weight = 1;
  const int without = WallPixelsInsideTheCard(off);
  const int with_default = WallPixelsInsideTheCard(SeamSkirtOptions());
  const int with_full = WallPixelsInsideTheCard(full);
  std::printf("card pixels showing the wall at the seam: %d without skirts, %d with (weight %.2f), %d (weight 1)\n",
              without,
              with_default,
              SeamSkirtOptions().weight,
              with_full);
  EXPECT_GE(without, 28)
      << "the seam must open (at least a pixel in each of the 28 rows) for this test to mean anything";
  EXPECT_EQ(with_default, 0);
  EXPECT_EQ(with_full, 0);
}

TEST(SeamSkirtsTest, SkirtsLieOnSameSurfaceSeamsOnlyAwayFromEdgesAndBorders) {
  const LayeredDepthView view = CardOverWall(1.04);
  SeamSkirtReport report;
  SeamSkirtOptions options;
  options.weight = 0.75f;
  const LayeredDepthView skirted = WithSeamSkirts(view, options, &report);
  // One texel each side of the seam x = 19 | 20 on the card's 32 rows; the card-wall border is a
  // depth edge (planes 67 % apart): none there, nor on the image's border.
  EXPECT_EQ(report.skirt_texels, 64);
  EXPECT_EQ(skirted.layers[1].segment.at<int32_t>(20, 19), kCardRight);
  EXPECT_EQ(skirted.layers[1].segment.at<int32_t>(20, 20), kCardLeft);
  EXPECT_EQ(skirted.layers[1].weight.at<float>(20, 20), 0.75f);
  EXPECT_EQ(skirted.layers[1].colour.at<cv::Vec3b>(20, 20), view.layers[0].colour.at<cv::Vec3b>(20, 20));
  EXPECT_EQ(skirted.layers[1].segment.at<int32_t>(20, 14), SegmentLayer::kNoSegment);
  EXPECT_EQ(skirted.segments[kCardLeft].bbox, cv::Rect(14, 8, 7, 32));  // grown by its skirt column
  EXPECT_EQ(skirted.segments[kCardRight].bbox, cv::Rect(19, 8, 31, 32));
  // The caller's view is not changed.
  EXPECT_EQ(view.layers[1].segment.at<int32_t>(20, 20), SegmentLayer::kNoSegment);
  EXPECT_EQ(view.segments[kCardLeft].bbox, cv::Rect(14, 8, 6, 32));
  // Planes further apart than max_step are a depth edge: no skirt.
  WithSeamSkirts(CardOverWall(1.2), options, &report);
  EXPECT_EQ(report.skirt_texels, 0);
  // Planes that agree to within min_step cannot part visibly: no skirt (the card's two halves on
  // one plane), unless the floor is 0.
  WithSeamSkirts(CardOverWall(1.0), options, &report);
  EXPECT_EQ(report.skirt_texels, 0);
  WithSeamSkirts(CardOverWall(1.0 + 0.5 * options.min_step), options, &report);
  EXPECT_EQ(report.skirt_texels, 0);
  WithSeamSkirts(CardOverWall(1.0 - 2 * options.min_step), options, &report);
  EXPECT_EQ(report.skirt_texels, 64);
  SeamSkirtOptions no_floor = options;
  no_floor.min_step = 0;
  WithSeamSkirts(CardOverWall(1.0), no_floor, &report);
  EXPECT_EQ(report.skirt_texels, 64);
  // Off.
  options.max_step = 0;
  WithSeamSkirts(view, options, &report);
  EXPECT_EQ(report.skirt_texels, 0);
}

TEST(SeamSkirtsTest, OptionsOutsideTheirRangesAreRefused) {
  RenderOptions options;
  EXPECT_TRUE(options.Validate().ok());
  options.seam_skirts.min_step = options.seam_skirts.max_step;
  EXPECT_FALSE(options.Validate().ok());
  options.seam_skirts.min_step = -1e-4;
  EXPECT_FALSE(options.Validate().ok());
  options.seam_skirts.min_step = 0;
  options.seam_skirts.max_step = 1;
  EXPECT_FALSE(options.Validate().ok());
  options.seam_skirts.max_step = 0;  // off: the floor does not matter
  options.seam_skirts.min_step = 0.5;
  EXPECT_TRUE(options.Validate().ok());
  options.seam_skirts.weight = 0;
  EXPECT_FALSE(options.Validate().ok());
}

}  // namespace
}  // namespace px::render
