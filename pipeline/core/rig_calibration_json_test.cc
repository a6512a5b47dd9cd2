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

TEST(RigCalibrationJsonTest, TileRotationRoundTripsAndIsOmittedWhenZero) {
  RigCalibration rig = Pop9Rig();
  rig.lattice.tiles[5].rotation_deg = -1.25;
  const nlohmann::json j = RigCalibrationToJson(rig);
  EXPECT_FALSE(j["lattice"]["tiles"][4].contains("rotation_deg"));  // older readers see no change
  EXPECT_EQ(j["lattice"]["tiles"][5]["rotation_deg"], -1.25);
  StatusOr<RigCalibration> back = RigCalibrationFromJson(j);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(back->lattice.tiles[5].rotation_deg, -1.25);
  EXPECT_EQ(back->lattice.tiles[4].rotation_deg, 0.0);

  nlohmann::json bad = j;
  bad["lattice"]["tiles"][5]["rotation_deg"] = 60;
  EXPECT_NE(RigCalibrationFromJson(bad).status().message().find("tile 5 rotation 60 deg is outside [-45, 45]"),
            std::string::npos)
      << RigCalibrationFromJson(bad).status().message();
  bad["lattice"]["tiles"][5]["rotation_deg"] = "tilted";
  EXPECT_EQ(RigCalibrationFromJson(bad).status().message(), "lattice.tiles[5].rotation_deg: want a number, got string");
}

TEST(LatticeLayoutTest, RotatedTileGeometry) {
  Tile tile;
  tile.rect = cv::Rect(100, 50, 41, 21);  // centre (120, 60)
  EXPECT_EQ(TileCentre(tile), cv::Point2d(120, 60));
  // Unrotated: the plain offset by the rect's top-left corner.
  cv::Matx23d m = SensorFromTile(tile);
  EXPECT_NEAR(m(0, 2), 100, 1e-12);
  EXPECT_NEAR(m(1, 2), 50, 1e-12);
  // Turned by 90 degrees clockwise (as displayed, y down): the tile's +u axis points down the sensor.
  tile.rotation_deg = 90;
  m = SensorFromTile(tile);
  const cv::Point2d right_of_centre(m(0, 0) * 30 + m(0, 1) * 10 + m(0, 2), m(1, 0) * 30 + m(1, 1) * 10 + m(1, 2));
  EXPECT_NEAR(right_of_centre.x, 120, 1e-9);
  EXPECT_NEAR(right_of_centre.y, 70, 1e-9);
  const std::array<cv::Point2d, 4> corners = TileCorners(tile);
  EXPECT_NEAR(corners[0].x, 120 + 10.5, 1e-9);  // top-left of the stored tile, now top-right on screen
  EXPECT_NEAR(corners[0].y, 60 - 20.5, 1e-9);
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
