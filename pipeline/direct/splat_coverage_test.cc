// HoleScoreAtOutputSize: H(V) from a reduced coverage mask, per hole pixel at the output size
// (splat_coverage.h). Compared with the same holes drawn at the output size itself.
#include "pipeline/direct/splat_coverage.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

namespace px::direct {
namespace {

// A covered `size` x `size` mask with a hole rectangle (in pixels of that mask).
cv::Mat WithHole(int size, const cv::Rect& hole) {
  cv::Mat covered(size, size, CV_8U, cv::Scalar(255));
  covered(hole).setTo(0);
  return covered;
}

TEST(HoleScoreAtOutputSize, IsThePapersSumAtFullSize) {
  // One hole pixel: d = 1, H = 1 / (w h).
  EXPECT_NEAR(HoleScoreAtOutputSize(WithHole(10, cv::Rect(4, 4, 1, 1)), 1.0), 1.0 / 100, 1e-9);
  EXPECT_DOUBLE_EQ(HoleScoreAtOutputSize(cv::Mat(10, 10, CV_8U, cv::Scalar(1)), 1.0), 0.0);
}

TEST(HoleScoreAtOutputSize, AWideHoleReadsAsAtTheOutputSize) {
  // A 20 x 20 hole in an 80 x 80 target at a quarter of the size, and the same at full size.
  const double reduced = HoleScoreAtOutputSize(WithHole(80, cv::Rect(30, 30, 20, 20)), 0.25);
  const double full = HoleScoreAtOutputSize(WithHole(320, cv::Rect(120, 120, 80, 80)), 1.0);
  EXPECT_NEAR(reduced / full, 1.0, 0.15) << reduced << " vs " << full;
}

TEST(HoleScoreAtOutputSize, AStripOneReducedPixelWideIsNotReadFourTimesOver) {
  // A border strip 4 output pixels wide is one pixel wide at a quarter of the size; d^3 / s^3
  // would read it (2 / (1 + s))^3 = 4.1 times over.
  const double reduced = HoleScoreAtOutputSize(WithHole(80, cv::Rect(0, 0, 1, 80)), 0.25);
  const double full = HoleScoreAtOutputSize(WithHole(320, cv::Rect(0, 0, 4, 320)), 1.0);
  EXPECT_NEAR(reduced / full, 1.0, 0.5) << reduced << " vs " << full;
}

}  // namespace
}  // namespace px::direct
