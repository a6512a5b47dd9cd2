#include "pipeline/direct/plan_move.h"

#include <gtest/gtest.h>

#include <cmath>

#include "pipeline/direct/test_scene.h"

namespace px::direct {
namespace {

SceneGeometry Scene() { return TestCaptureScene(); }

SceneSamples WallSamples(const SceneGeometry& scene) {
  View view;
  view.id = ViewId{0};
  view.camera = scene.output;
  view.image = cv::Mat(480, 640, CV_8UC3, cv::Scalar(128, 128, 128));
  DepthMap depth;
  depth.id = view.id;
  depth.depth_m = cv::Mat(480, 640, CV_32F, cv::Scalar(1.5));
  depth.confidence = cv::Mat(480, 640, CV_32F, cv::Scalar(1.0));
  return SceneSamples::FromDepths({view}, {depth});
}

constexpr double kFrontZ = 0.25;                          // the valid slab's front
constexpr double kIslandNearZ = 0.28, kIslandFarZ = 0.6;  // the island's extent in z
constexpr double kIslandX = 0.09, kIslandY = 0.09;        // the island's column is beyond these

// Valid (H(V) 0) in a slab from 0.5 m back to kFrontZ forwards, except in the grid's far corner
// column, where only an island far forwards is valid: the search finds that column's valid
// position far ahead, and every path there crosses invalid space.
StatusOr<CoverageReport> SlabWithIsland(const CameraModel& camera, const Rigid3& cam_from_world) {
  const Eigen::Vector3d c = CameraCentre(cam_from_world);
  const bool island_column = c.x() > kIslandX && c.y() > kIslandY;
  const bool valid =
      island_column ? (c.z() >= kIslandNearZ && c.z() <= kIslandFarZ) : (c.z() <= kFrontZ && c.z() >= -0.5);
  return ValidityCoverage(camera, valid);
}

TEST(PlanMoveTest, PathsThroughAnIslandOfValidViewpointsGiveWayToOnesThatHold) {
  const SceneGeometry scene = Scene();
  const SceneSamples samples = WallSamples(scene);
  const CoverageFunction coverage = SlabWithIsland;
  CoverageProbe search(&coverage, 1.0, 2.0);
  CoverageProbe verify(&coverage, 1.0, 2.0);
  const DirectOptions options;
  PlanContext context;
  context.scene = &scene;
  context.samples = &samples;
  context.search = &search;
  context.verify = &verify;
  context.options = &options;
  MoveChoice choice;
  choice.move = Move::kEstablishingDolly;
  MovePlanReport report;
  // With one batch every path tried leads to the island, and the move cannot be planned.
  EXPECT_FALSE(PlanMove(choice, context, &report).ok());
  context.path_batches = 3;
  context.first_batch = 1;  // as the caller does once one batch has failed
  StatusOr<CameraPath> path = PlanMove(choice, context, &report);
  ASSERT_TRUE(path.ok()) << path.status().ToString();
  // The second batch, without the island's end, is the only one measured again; a path within
  // the slab holds.
  EXPECT_EQ(report.paths_measured, options.search.num_longest);
  for (const CameraKeyframe& key : path->keyframes) {
    EXPECT_LE(key.centre_in_world.z(), kFrontZ + 1e-9);
    EXPECT_FALSE(key.centre_in_world.x() > kIslandX && key.centre_in_world.y() > kIslandY);
  }
  EXPECT_LT(report.max_hole_score, 2.0);
}

}  // namespace
}  // namespace px::direct
