#include "pipeline/core/rig_calibration_json.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace px {
namespace {

RigCalibration Pop9Rig() {
  RigCalibration rig;
  rig.rig_name = "test-pop9";
  rig.lattice = LatticeLayout::Regular(3, 3, 160, 120, 8, TileOrientation::kRotated180);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      LensCalibration lens;
      lens.camera = CameraModel::Pinhole(160, 120, 150 + r + c);
      lens.camera.distortion = {-0.05 * r, 0.01, 0, 0, 0};
      lens.cam_from_rig = Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(0.01 * c, Eigen::Vector3d::UnitY())),
                                 {-0.02 * (c - 1), -0.02 * (r - 1), 0});
      rig.lenses.push_back(lens);
    }
  }
  return rig;
}

TEST(RigCalibrationJsonTest, RoundTripsExactly) {
  const RigCalibration rig = Pop9Rig();
  StatusOr<RigCalibration> back = RigCalibrationFromJsonText(RigCalibrationToJsonText(rig));
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  ASSERT_EQ(back->NumViews(), 9);
  EXPECT_EQ(back->rig_name, "test-pop9");
  EXPECT_EQ(back->lattice.tiles[4].rect, rig.lattice.tiles[4].rect);
  EXPECT_EQ(back->lattice.tiles[4].orientation, TileOrientation::kRotated180);
  for (int i = 0; i < 9; ++i) {
    EXPECT_DOUBLE_EQ(back->lenses[i].camera.fx, rig.lenses[i].camera.fx);
    EXPECT_DOUBLE_EQ(back->lenses[i].camera.distortion[0], rig.lenses[i].camera.distortion[0]);
    EXPECT_TRUE(back->lenses[i].cam_from_rig.translation.isApprox(rig.lenses[i].cam_from_rig.translation));
    EXPECT_LT(RotationErrorDeg(back->lenses[i].cam_from_rig, rig.lenses[i].cam_from_rig), 1e-9);
  }
}

TEST(RigCalibrationJsonTest, ErrorsNameTheField) {
  nlohmann::json j = RigCalibrationToJson(Pop9Rig());
  j["lenses"][3]["camera"].erase("fx");
  EXPECT_EQ(RigCalibrationFromJson(j).status().message(), "lenses[3].camera.fx: missing");

  j = RigCalibrationToJson(Pop9Rig());
  j["lenses"][2]["cam_from_rig"]["translation_m"] = "far";
  EXPECT_EQ(RigCalibrationFromJson(j).status().message(),
            "lenses[2].cam_from_rig.translation_m: want an array of numbers, got string");

  j = RigCalibrationToJson(Pop9Rig());
  j["version"] = 99;
  EXPECT_NE(RigCalibrationFromJson(j).status().message().find("version: 99 is not a supported version"),
            std::string::npos);
}

TEST(RigCalibrationJsonTest, InconsistentRigIsRejected) {
  RigCalibration rig = Pop9Rig();
  rig.lenses.pop_back();
  StatusOr<RigCalibration> back = RigCalibrationFromJson(RigCalibrationToJson(rig));
  ASSERT_FALSE(back.ok());
  EXPECT_NE(back.status().message().find("9 tiles but 8 lenses"), std::string::npos) << back.status().message();
}

TEST(RigCalibrationJsonTest, MalformedTextNamesTheOffset) {
  StatusOr<RigCalibration> back = RigCalibrationFromJsonText("{\"schema\": ");
  ASSERT_FALSE(back.ok());
  EXPECT_NE(back.status().message().find("malformed JSON at byte"), std::string::npos);
}

}  // namespace
}  // namespace px
