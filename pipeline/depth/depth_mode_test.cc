#include "pipeline/depth/depth_mode.h"

#include <gtest/gtest.h>

namespace px {
namespace {

// A rows x cols grid of views `pitch_m` apart facing +z, `focal_px` each (only poses and
// intrinsics matter to the choice).
std::vector<View> Grid(int rows, int cols, double pitch_m, double focal_px) {
  std::vector<View> views;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      View view;
      view.id = ViewId(static_cast<int>(views.size()));
      view.camera = CameraModel::Pinhole(640, 480, focal_px);
      view.cam_from_world = Rigid3(Eigen::Quaterniond::Identity(), -Eigen::Vector3d(c * pitch_m, r * pitch_m, 0));
      views.push_back(view);
    }
  }
  return views;
}

DepthOptions WithRange(double min_m, double max_m) {
  DepthOptions options;
  options.min_depth_m = min_m;
  options.max_depth_m = max_m;
  return options;
}

TEST(DepthModeTest, APlenopticGridIsALightField) {
  // A Lytro-like 5x5: 0.5 mm apart, 550 px focal, 0.3 to 3 m: 0.8 px between neighbours.
  const DepthModeChoice choice = ChooseDepthMode(Grid(5, 5, 0.0005, 550), WithRange(0.3, 3.0));
  EXPECT_TRUE(choice.light_field) << choice.reason;
  EXPECT_NEAR(choice.neighbour_disparity_px, 550 * 0.0005 * (1 / 0.3 - 1 / 3.0), 1e-9);
  EXPECT_EQ(choice.options.mode, DepthMode::kLightField);
  EXPECT_EQ(choice.options.working_scale, 1.0);
  EXPECT_EQ(choice.options.matching.plane_step_px, LightFieldDepthOptions(DepthOptions()).matching.plane_step_px);
  // The depth range and threads are the caller's, not the light-field defaults'.
  EXPECT_EQ(choice.options.min_depth_m, 0.3);
  EXPECT_EQ(choice.options.max_depth_m, 3.0);
}

TEST(DepthModeTest, ALatticeOfWideBaselinesIsNot) {
  // The Pop9: 25 mm apart, 560 px, 0.5 to 8 m: 26 px between neighbours.
  const DepthModeChoice choice = ChooseDepthMode(Grid(3, 3, 0.025, 560), WithRange(0.5, 8.0));
  EXPECT_FALSE(choice.light_field) << choice.reason;
  EXPECT_GT(choice.neighbour_disparity_px, 20);
  EXPECT_EQ(choice.options.mode, DepthMode::kAuto);
  EXPECT_EQ(choice.options.working_scale, DepthOptions().working_scale);
}

TEST(DepthModeTest, TheIntegralLensRendersBetterWithTheStandardSet) {
  // The simulated 5x4 integral lens: 12 mm apart, 280 px, 0.5 to 8 m: 6.3 px between neighbours.
  const DepthModeChoice choice = ChooseDepthMode(Grid(4, 5, 0.012, 280), WithRange(0.5, 8.0));
  EXPECT_FALSE(choice.light_field) << choice.reason;
  EXPECT_NEAR(choice.neighbour_disparity_px, 6.3, 0.05);
}

TEST(DepthModeTest, TooFewViewsAreNeverALightField) {
  // Four views a fraction of a pixel apart: too few neighbours to agree on sub-pixel matches.
  const DepthModeChoice choice = ChooseDepthMode(Grid(2, 2, 0.0005, 550), WithRange(0.3, 3.0));
  EXPECT_FALSE(choice.light_field);
  EXPECT_NE(choice.reason.find("4 views"), std::string::npos) << choice.reason;
}

TEST(DepthModeTest, AModeAskedForIsTaken) {
  DepthOptions standard = WithRange(0.3, 3.0);
  standard.mode = DepthMode::kStandard;
  EXPECT_FALSE(ChooseDepthMode(Grid(5, 5, 0.0005, 550), standard).light_field);
  DepthOptions light_field = WithRange(0.5, 8.0);
  light_field.mode = DepthMode::kLightField;
  const DepthModeChoice choice = ChooseDepthMode(Grid(3, 3, 0.025, 560), light_field);
  EXPECT_TRUE(choice.light_field);
  EXPECT_EQ(choice.options.working_scale, 1.0);
}

TEST(DepthModeTest, TheThresholdsAreValidated) {
  DepthOptions options = WithRange(0.3, 3.0);
  options.light_field_max_disparity_px = 0;
  EXPECT_FALSE(options.Validate().ok());
  options = WithRange(0.3, 3.0);
  options.light_field_min_views = 1;
  EXPECT_FALSE(options.Validate().ok());
}

}  // namespace
}  // namespace px
