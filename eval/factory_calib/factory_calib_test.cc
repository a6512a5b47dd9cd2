// Factory rig calibration of the simulated 3x3 and 5x4 rigs (barrel distortion, vignetting,
// noise) from simulated board captures, against their truth; and its refusals.
#include <gtest/gtest.h>

#include "eval/factory_calib/factory_calib_eval.h"
#include "pipeline/lattice/split_lattice.h"

namespace px::eval {
namespace {

// Thresholds, from what 8 captures of a 7x5 board filling the middle 55-75 % of each 320x240
// tile reach (measured: focal 0.8-1.7 %, principal point ~1 px, 3-4 px at the tile corners where
// the board never reaches, rotation 0.25-0.35 deg, centres 2-6 % of the baseline; see
// pipeline/calib/README.md), with about 2x margin. They catch a broken pose chain or distortion
// model (degrees, tens of pixels), not the last percent: corner coverage (ChArUco boards seen
// partially) is what would tighten them.
constexpr double kMaxFocalPct = 3.0;
constexpr double kMaxPrincipalPointPx = 3.0;
constexpr double kMaxCornerPx = 8.0;
constexpr double kMaxRotationDeg = 0.7;
constexpr double kMaxCentreOfBaseline = 0.12;

void ExpectCalibrated(const FactoryCalibCase& c) {
  StatusOr<FactoryCalibRow> row = EvaluateFactoryCalibration(c);
  ASSERT_TRUE(row.ok()) << c.name << ": " << row.status().message();
  std::printf("%s", FormatFactoryCalibRow(*row).c_str());
  EXPECT_LT(row->error.focal_pct, kMaxFocalPct);
  EXPECT_LT(row->error.principal_point_px, kMaxPrincipalPointPx);
  EXPECT_LT(row->error.corner_reprojection_px, kMaxCornerPx);
  EXPECT_LT(row->error.rotation_deg, kMaxRotationDeg);
  EXPECT_LT(row->error.centre_of_baseline, kMaxCentreOfBaseline);
  ASSERT_EQ(row->result.report.tiles.size(), static_cast<size_t>(c.spec.rows * c.spec.cols));
  for (const TileCalibrationFigures& t : row->result.report.tiles) {
    EXPECT_GE(t.boards_found, c.captures - 2) << "tile " << t.view;  // a tilted board may leave an outer tile
    EXPECT_LT(t.rms_px, 0.3) << "tile " << t.view;
  }
}

TEST(FactoryCalibTest, Calibrates3x3RigFromBoardCaptures) { ExpectCalibrated(StandardFactoryCalibCases(0.5)[0]); }
TEST(FactoryCalibTest, Calibrates5x4RigFromBoardCaptures) { ExpectCalibrated(StandardFactoryCalibCases(0.5)[1]); }

TEST(FactoryCalibTest, TooFewCapturesAreRefused) {
  FactoryCalibCase c = StandardFactoryCalibCases(0.5)[0];
  c.captures = 2;
  StatusOr<FactoryCalibRow> row = EvaluateFactoryCalibration(c);
  ASSERT_FALSE(row.ok());
  EXPECT_EQ(row.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(row.status().message().find("too few captures: 2"), std::string::npos) << row.status().message();
}

TEST(FactoryCalibTest, ATileWithoutTheBoardIsNamed) {
  const FactoryCalibCase c = StandardFactoryCalibCases(0.5)[0];
  StatusOr<std::vector<sim::BoardCapture>> captures =
      sim::RenderBoardCaptures(c.spec, c.board, sim::BoardPoses(c.board, c.spec, 3, c.seed), c.seed);
  ASSERT_TRUE(captures.ok()) << captures.status().message();
  const LatticeLayout layout = c.spec.Layout();
  std::vector<std::vector<cv::Mat>> tiles;
  for (const sim::BoardCapture& capture : *captures) {
    StatusOr<std::vector<cv::Mat>> split = SplitLattice(capture.sensor_bgr, layout);
    ASSERT_TRUE(split.ok());
    (*split)[5].setTo(cv::Scalar::all(90));  // a lens covered in every capture
    tiles.push_back(*split);
  }
  RigCalibratorOptions options;
  options.board = ToCalibrationBoard(c.board);
  StatusOr<RigCalibrationResult> result = CalibrateRig(tiles, layout, options);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().code(), StatusCode::kNotFound);
  EXPECT_NE(result.status().message().find("tile 5 (row 1, col 2)"), std::string::npos) << result.status().message();
  EXPECT_NE(result.status().message().find("0 of 3"), std::string::npos) << result.status().message();
}

}  // namespace
}  // namespace px::eval
