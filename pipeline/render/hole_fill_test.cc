#include "pipeline/render/hole_fill.h"

#include <gtest/gtest.h>

namespace px::render {
namespace {

TEST(HoleScoreTest, SumsCubedDistancesOverTheArea) {
  cv::Mat coverage(40, 50, CV_8U, cv::Scalar(255));
  EXPECT_EQ(HoleScore(coverage), 0.0);
  // A one-pixel-wide line: every hole pixel is 1 px from covered ones.
  coverage(cv::Rect(10, 5, 1, 20)).setTo(0);
  EXPECT_NEAR(HoleScore(coverage), 20.0 / (40 * 50), 1e-9);
  // A wide hole scores far more than the same area spread thin (the metric's point).
  cv::Mat block(40, 50, CV_8U, cv::Scalar(255));
  block(cv::Rect(10, 10, 20, 20)).setTo(0);
  cv::Mat lines(40, 50, CV_8U, cv::Scalar(255));
  for (int i = 0; i < 20; ++i) lines(cv::Rect(5 + 2 * i, 10, 1, 20)).setTo(0);
  EXPECT_GT(HoleScore(block), 20 * HoleScore(lines));
}

TEST(FillHolesTest, SmallHolesTakeTheFartherSide) {
  // A near surface (1 m, red) left of a far one (3 m, blue) with a 3 px gap between them, as a
  // camera moving right uncovers background beside a foreground edge.
  cv::Mat bgr(20, 30, CV_8UC3, cv::Scalar(255, 0, 0));
  cv::Mat depth(20, 30, CV_32F, cv::Scalar(3.0f));
  bgr(cv::Rect(0, 0, 12, 20)).setTo(cv::Scalar(0, 0, 255));
  depth(cv::Rect(0, 0, 12, 20)).setTo(1.0f);
  cv::Mat coverage(20, 30, CV_8U, cv::Scalar(255));
  coverage(cv::Rect(12, 0, 3, 20)).setTo(0);
  const HoleFillReport report = FillHoles(coverage, 3, 0.05f, &bgr, &depth);
  EXPECT_EQ(report.hole_pixels, 60);
  EXPECT_EQ(report.filled_from_far, 60);
  EXPECT_EQ(report.propagated, 0);
  for (int y = 0; y < 20; ++y) {
    for (int x = 12; x < 15; ++x) {
      EXPECT_EQ(bgr.at<cv::Vec3b>(y, x), cv::Vec3b(255, 0, 0)) << x << "," << y;
      EXPECT_FLOAT_EQ(depth.at<float>(y, x), 3.0f);
    }
  }
}

TEST(FillHolesTest, LargeHolesCarryTheBackgroundAcross) {
  // A 20 px wide disocclusion between a near red surface (left) and a far blue one (right):
  // wider than the fill radius, so it is filled ring by ring, and only from the far side.
  cv::Mat bgr(40, 60, CV_8UC3, cv::Scalar(255, 0, 0));
  cv::Mat depth(40, 60, CV_32F, cv::Scalar(3.0f));
  bgr(cv::Rect(0, 0, 20, 40)).setTo(cv::Scalar(0, 0, 255));
  depth(cv::Rect(0, 0, 20, 40)).setTo(1.0f);
  cv::Mat coverage(40, 60, CV_8U, cv::Scalar(255));
  coverage(cv::Rect(20, 0, 20, 40)).setTo(0);
  bgr.setTo(cv::Scalar(0, 0, 0), coverage == 0);
  depth.setTo(0, coverage == 0);
  const HoleFillReport report = FillHoles(coverage, 3, 0.05f, &bgr, &depth);
  EXPECT_EQ(report.hole_pixels, 800);
  // The first ring reaches 3 px in from the background side only; the rest propagates.
  EXPECT_EQ(report.filled_from_far, 3 * 40);
  EXPECT_EQ(report.propagated, 17 * 40);
  for (int y = 0; y < 40; ++y) {
    for (int x = 20; x < 40; ++x) {
      ASSERT_EQ(bgr.at<cv::Vec3b>(y, x), cv::Vec3b(255, 0, 0)) << x << "," << y;
      ASSERT_FLOAT_EQ(depth.at<float>(y, x), 3.0f) << x << "," << y;
    }
  }
}

TEST(FillHolesTest, FillsAnIsolatedHoleFromItsSurround) {
  // A hole in the middle of one surface fills with that surface (a smooth ramp stays a ramp).
  cv::Mat bgr(60, 60, CV_8UC3);
  for (int x = 0; x < 60; ++x) bgr.col(x).setTo(cv::Scalar(2 * x, 100, 200 - 2 * x));
  const cv::Mat original = bgr.clone();
  cv::Mat depth(60, 60, CV_32F, cv::Scalar(2.0f));
  cv::Mat coverage(60, 60, CV_8U, cv::Scalar(255));
  coverage(cv::Rect(20, 20, 20, 20)).setTo(0);
  bgr.setTo(cv::Scalar(0, 0, 0), coverage == 0);
  const HoleFillReport report = FillHoles(coverage, 3, 0.05f, &bgr, &depth);
  EXPECT_EQ(report.filled_from_far + report.propagated, 400);
  cv::Mat diff;
  cv::absdiff(bgr, original, diff);
  // Filling by weighted means diffuses: the inside flattens towards the mean of its rim. Within
  // half of the 40 levels the ramp rises across the hole, and never black.
  EXPECT_LE(cv::norm(diff, cv::NORM_INF), 20.0);
  EXPECT_FLOAT_EQ(depth.at<float>(30, 30), 2.0f);
}

}  // namespace
}  // namespace px::render
