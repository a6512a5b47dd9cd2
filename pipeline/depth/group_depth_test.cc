// Group depth: a textured wall behind a square, its plane set 1.5 % too near or too far, comes
// back to its true depth from the other views; a right plane stays; a textureless wall and a
// group too small for an interior are left alone.
#include "pipeline/depth/group_depth.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "pipeline/depth/depth_stage_test_util.h"

namespace px::depth {
namespace {

constexpr int kCentre = testing::SquareFromView::kCentre;
constexpr double kSquareDepthM = testing::SquareFromView::kSquareDepthM;
constexpr double kWallDepthM = testing::SquareFromView::kWallDepthM;

struct Scene : testing::SquareFromView {
  SegmentImage image;  // label 0 the wall, label 1 the square, exact planes
};

Scene SquareScene(bool textured_wall = true) {
  Scene scene;
  static_cast<testing::SquareFromView&>(scene) = testing::MakeSquareFromView();
  if (!textured_wall) {
    // A flat grey wall alone (the labels keep the square's outline).
    testing::TexturedPlane grey = testing::Wall(kWallDepthM, 1);
    grey.texture.setTo(cv::Scalar::all(128));
    scene.views = testing::RenderGridRig(3, 3, testing::kStageBaselineM, testing::SmallCamera(), {grey});
  }
  scene.image.labels = cv::Mat::zeros(scene.square.size(), CV_32S);
  scene.image.labels.setTo(1, scene.square);
  scene.image.planes = {InversePlane{0, 0, 1 / kWallDepthM}, InversePlane{0, 0, 1 / kSquareDepthM}};
  scene.image.confidence = {1.0f, 1.0f};
  return scene;
}

GroupDepthStats Refine(Scene* scene, const std::vector<int>& group_of) {
  std::vector<WorkingView> working;
  for (const View& view : scene->views) working.push_back(MakeWorkingView(view, 1.0));
  std::vector<const WorkingView*> neighbours;
  for (int i = 0; i < static_cast<int>(working.size()); ++i) {
    if (i != kCentre) neighbours.push_back(&working[i]);
  }
  GroupDepthOptions options;
  options.pixel_inverse_depth = Scene::PixelInverseDepth();
  return RefineGroupDepths(working[kCentre], neighbours, group_of, options, &scene->image);
}

// The wall's plane relative to the truth, minus 1 (positive: too near).
double WallError(const Scene& scene) { return scene.image.planes[0].c * kWallDepthM - 1; }

TEST(GroupDepthTest, AWallTooNearOrTooFarComesBack) {
  for (double error : {0.015, -0.015}) {
    Scene scene = SquareScene();
    scene.image.planes[0].c *= 1 + error;  // 0.05 px of disparity against the nearest neighbour
    const GroupDepthStats stats = Refine(&scene, {0, -1});
    std::printf("wall %+.1f %% off -> %+.3f %% (%d group searched, %.3f px moved)\n",
                100 * error,
                100 * WallError(scene),
                stats.groups,
                stats.mean_abs_shift_px);
    EXPECT_EQ(stats.groups, 1);
    EXPECT_LT(std::abs(WallError(scene)), 0.001) << "start " << error;  // measured 0.000 %
    EXPECT_EQ(scene.image.planes[1].c, 1 / kSquareDepthM) << "the square is in no group";
  }
}

TEST(GroupDepthTest, ARightPlaneStays) {
  Scene scene = SquareScene();
  Refine(&scene, {0, -1});
  EXPECT_LT(std::abs(WallError(scene)), 0.001);
}

TEST(GroupDepthTest, ATexturelessWallIsLeftAlone) {
  Scene scene = SquareScene(/*textured_wall=*/false);
  scene.image.planes[0].c *= 1.015;
  const GroupDepthStats stats = Refine(&scene, {0, -1});
  EXPECT_EQ(stats.groups, 0);
  EXPECT_NEAR(WallError(scene), 0.015, 1e-12);
}

TEST(GroupDepthTest, AGroupWithoutInteriorIsLeftAlone) {
  Scene scene = SquareScene();
  scene.image.planes[1].c *= 1.015;
  // The square (90 x 72 px) has an interior; one 20 px wide does not.
  scene.image.labels.setTo(0);
  scene.image.labels(cv::Rect(150, 100, 20, 40)).setTo(1);
  const GroupDepthStats stats = Refine(&scene, {-1, 0});
  EXPECT_EQ(stats.groups, 0);
  EXPECT_EQ(stats.moved, 0);
}

}  // namespace
}  // namespace px::depth
