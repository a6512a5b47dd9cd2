#include "eval/render/crack_measure.h"

#include <gtest/gtest.h>

namespace px::eval {
namespace {

// A card at 1 m over a wall at 3 m, 60x40: the card covers x in [10, 50).
cv::Mat CardOverWall() {
  cv::Mat depth(40, 60, CV_32F, cv::Scalar(3.0f));
  depth(cv::Rect(10, 0, 40, 40)).setTo(1.0f);
  return depth;
}

TEST(CrackMeasureTest, ThinLinesOfTheWallInsideTheCardAreCracks) {
  const cv::Mat truth = CardOverWall();
  cv::Mat rendered = truth.clone();
  rendered.col(20).setTo(3.0f);                  // 1 px vertical crack: 40 px
  rendered(cv::Rect(30, 10, 3, 1)).setTo(2.0f);  // part of a row, 3 px wide, mixed depth: 3 px
  rendered(cv::Rect(36, 20, 2, 1)).setTo(3.0f);  // 2 px wide: 2 px
  cv::Mat map;
  const CrackReport report = MeasureCracks(rendered, truth, {}, &map);
  EXPECT_EQ(report.crack_pixels, 45);
  EXPECT_NEAR(report.crack_fraction, 45.0 / (60 * 40), 1e-12);
  EXPECT_EQ(map.at<uint8_t>(5, 20), 255);
  EXPECT_EQ(map.at<uint8_t>(5, 21), 0);
}

TEST(CrackMeasureTest, WideHolesRealGapsAndSmallDepthErrorsAreNotCracks) {
  const cv::Mat truth = CardOverWall();
  cv::Mat rendered = truth.clone();
  rendered(cv::Rect(20, 0, 6, 40)).setTo(3.0f);  // 6 px wide: a hole, not a crack
  rendered.col(40).setTo(1.05f);                 // 5 % behind: a depth error, not the wall
  cv::Mat gap_truth = truth.clone();
  gap_truth.col(45).setTo(3.0f);  // the scene has a 1 px gap there: rendered right
  rendered.col(45).setTo(3.0f);
  EXPECT_EQ(MeasureCracks(rendered, gap_truth).crack_pixels, 0);
}

TEST(CrackMeasureTest, PixelsWithoutTrueDepthAreLeftOut) {
  cv::Mat truth = CardOverWall();
  truth.row(0).setTo(0.0f);  // nothing hit
  cv::Mat rendered = truth.clone();
  rendered.row(0).setTo(3.0f);
  const CrackReport report = MeasureCracks(rendered, truth);
  EXPECT_EQ(report.crack_pixels, 0);
  EXPECT_EQ(report.crack_fraction, 0.0);
}

}  // namespace
}  // namespace px::eval
