// Per-shot refinement on simulated lattice shots that cannot support it, in part or at all
// (a blank or overexposed lens, a lens seeing another scene, a textureless scene, a planar or
// distant wall) and contradictory input: each keeps the best honest calibration, with a reason.
#include <gtest/gtest.h>

#include <cstdio>

#include "eval/calib/pose_alignment.h"
#include "eval/calib/sim_lattice_shot.h"
#include "pipeline/calib/rig_refinement.h"
#include "tests/testing/temp_dir.h"

namespace px::sim_calib {
namespace {

using eval::CaptureLatticeShot;
using eval::HalfSize;
using eval::LatticeShot;
using eval::RealisticSpec;
using eval::WritePlaneScene;

// Bad input. Each shot keeps the best honest calibration: lenses that cannot be refined keep
// the factory's, named in a warning; a shot that cannot be refined at all keeps the factory's
// with the reason. Half-size tiles keep these fast.
class RigRefinementBadInputTest : public ::testing::Test {
 protected:
  static LatticeShot Shot(const std::string& scene, uint64_t perturb_seed = 3) {
    StatusOr<LatticeShot> shot =
        CaptureLatticeShot(HalfSize(RealisticSpec(SimCameraSpec::Pop9(), perturb_seed)), scene);
    EXPECT_TRUE(shot.ok()) << shot.status().ToString();
    return shot.ok() ? *shot : LatticeShot{};
  }
  static calib::RigRefinementResult Refine(const LatticeShot& shot) {
    StatusOr<calib::RigRefinementResult> result =
        calib::RefineRigCalibration(shot.tiles, shot.factory, calib::RigRefinementOptions());
    EXPECT_TRUE(result.ok()) << result.status().ToString();
    if (!result.ok()) return {};
    for (const std::string& warning : result->report.warnings) std::printf("  warning: %s\n", warning.c_str());
    if (!result->report.refined) std::printf("  fallback: %s\n", result->report.fallback_reason.c_str());
    return *result;
  }
  static bool IsFactory(const RigCalibration& rig, const RigCalibration& factory, int lens) {
    return rig.lenses[lens].camera.fx == factory.lenses[lens].camera.fx &&
           rig.lenses[lens].cam_from_rig.translation == factory.lenses[lens].cam_from_rig.translation;
  }
  px::testing::TempDir temp_;
};

TEST_F(RigRefinementBadInputTest, BlankAndOverexposedViewsKeepTheFactoryCalibration) {
  LatticeShot shot = Shot("still_life");
  shot.tiles[4].setTo(cv::Scalar(0, 0, 0));        // a covered lens
  shot.tiles[7].setTo(cv::Scalar(255, 255, 255));  // a lens staring into the sun
  const calib::RigRefinementResult result = Refine(shot);
  ASSERT_TRUE(result.report.refined) << result.report.fallback_reason;
  EXPECT_TRUE(IsFactory(result.rig, shot.factory, 4));
  EXPECT_TRUE(IsFactory(result.rig, shot.factory, 7));
  EXPECT_FALSE(IsFactory(result.rig, shot.factory, 0));
  EXPECT_NE(result.report.views[4].note.find("blank"), std::string::npos) << result.report.views[4].note;
  EXPECT_NE(result.report.views[7].note.find("blank"), std::string::npos) << result.report.views[7].note;
  // The two views come first (at half size the scene may also be too shallow to fix lens centres).
  ASSERT_GE(result.report.warnings.size(), 2u);
  EXPECT_NE(result.report.warnings[0].find("view 4"), std::string::npos);
  EXPECT_NE(result.report.warnings[0].find("keeps its factory calibration"), std::string::npos);
  EXPECT_NE(result.report.warnings[1].find("view 7"), std::string::npos);
}

TEST_F(RigRefinementBadInputTest, ViewOfAnotherSceneKeepsTheFactoryCalibration) {
  LatticeShot shot = Shot("still_life");
  const LatticeShot other = Shot("two_faces");
  shot.tiles[2] = other.tiles[6];
  const calib::RigRefinementResult result = Refine(shot);
  ASSERT_TRUE(result.report.refined) << result.report.fallback_reason;
  EXPECT_TRUE(IsFactory(result.rig, shot.factory, 2));
  EXPECT_NE(result.report.views[2].note.find("a different scene"), std::string::npos) << result.report.views[2].note;
}

TEST_F(RigRefinementBadInputTest, TexturelessSceneFallsBackToTheFactoryCalibration) {
  const std::filesystem::path scene = temp_.path() / "flat.json";
  WritePlaneScene(scene, 1.5, R"({"type": "flat", "rgb": [120, 130, 140]})");
  const LatticeShot shot = Shot(scene.string());
  const calib::RigRefinementResult result = Refine(shot);
  EXPECT_FALSE(result.report.refined);
  EXPECT_NE(result.report.fallback_reason.find("too few features"), std::string::npos) << result.report.fallback_reason;
  for (int i = 0; i < shot.factory.NumViews(); ++i) EXPECT_TRUE(IsFactory(result.rig, shot.factory, i));
}

// A textured wall (all points on one plane) and the same wall 200 m away (no parallax at all):
// lens positions cannot be told from the matches, so they stay at the factory's, said in a
// warning; rotations and focal lengths are still refined, and still right.
TEST_F(RigRefinementBadInputTest, PlanarAndDistantScenesHoldLensCentres) {
  const std::string noise =
      R"({"type": "noise", "rgb_a": [220, 200, 160], "rgb_b": [40, 50, 70], "scale_m": 0.5, "octaves": 8,
          "persistence": 0.7, "contrast": 2.0, "seed": 3})";
  for (double distance : {1.5, 200.0}) {
    const std::filesystem::path scene = temp_.path() / ("wall_" + std::to_string(distance) + ".json");
    WritePlaneScene(scene,
                    distance,
                    distance > 10 ? R"({"type": "noise", "rgb_a": [220, 200, 160], "rgb_b": [40, 50, 70],
        "scale_m": 60, "octaves": 8, "persistence": 0.7, "contrast": 2.0, "seed": 3})"
                                  : noise);
    const LatticeShot shot = Shot(scene.string());
    const calib::RigRefinementResult result = Refine(shot);
    ASSERT_TRUE(result.report.refined) << "wall at " << distance << " m: " << result.report.fallback_reason;
    EXPECT_TRUE(result.report.centres_held) << "wall at " << distance << " m";
    ASSERT_FALSE(result.report.warnings.empty());
    EXPECT_NE(result.report.warnings.back().find("planar or too far"), std::string::npos);
    for (int i = 0; i < shot.factory.NumViews(); ++i) {
      EXPECT_LT(
          (CameraCentre(result.rig.lenses[i].cam_from_rig) - CameraCentre(shot.factory.lenses[i].cam_from_rig)).norm(),
          1e-9);
    }
    const StatusOr<eval::PoseErrors> after = eval::CompareRigs(result.rig, shot.truth);
    const StatusOr<eval::PoseErrors> before = eval::CompareRigs(shot.factory, shot.truth);
    ASSERT_TRUE(after.ok() && before.ok());
    const double rotation_before = eval::PoseErrors::Max(before->rotation_deg);
    const double rotation_after = eval::PoseErrors::Max(after->rotation_deg);
    std::printf("wall at %.0f m: rotation %.3f -> %.3f deg, focal %.2f -> %.2f %%\n",
                distance,
                rotation_before,
                rotation_after,
                100 * eval::PoseErrors::Max(before->focal_relative),
                100 * eval::PoseErrors::Max(after->focal_relative));
    EXPECT_LT(rotation_after, rotation_before);
  }
}

TEST(RigRefinementInputTest, ContradictoryInputIsAnError) {
  const SimCameraSpec spec = HalfSize(SimCameraSpec::Pop9());
  const RigCalibration rig = spec.Calibration();
  std::vector<cv::Mat> tiles(9, cv::Mat(spec.tile_height, spec.tile_width, CV_8UC3, cv::Scalar(0, 0, 0)));
  StatusOr<calib::RigRefinementResult> result =
      calib::RefineRigCalibration({tiles.begin(), tiles.begin() + 8}, rig, calib::RigRefinementOptions());
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().message(), "rig refinement: got 8 tiles, rig 'sim-pop9' has 9 lenses");
  tiles[3] = cv::Mat(10, 10, CV_8UC3);
  result = calib::RefineRigCalibration(tiles, rig, calib::RigRefinementOptions());
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().message(), "rig refinement: view 3 is 10x10, lens intrinsics are for 320x240");
  calib::RigRefinementOptions bad;
  bad.max_rotation_change_deg = 0;
  result = calib::RefineRigCalibration(tiles, rig, bad);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.status().message().find("max_rotation_change_deg = 0"), std::string::npos);
  calib::RigRefinementOptions disabled;
  disabled.enabled = false;
  tiles[3] = tiles[0];
  result = calib::RefineRigCalibration(tiles, rig, disabled);
  ASSERT_TRUE(result.ok());
  EXPECT_FALSE(result->report.refined);
  EXPECT_EQ(result->report.fallback_reason, "per-shot refinement is disabled");
}

}  // namespace
}  // namespace px::sim_calib
