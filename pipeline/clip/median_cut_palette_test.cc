#include "pipeline/clip/median_cut_palette.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <set>

namespace px::clip {
namespace {

TEST(MedianCutPaletteTest, FewColoursAreKeptExactly) {
  const std::vector<cv::Vec3b> colours = {{0, 0, 0}, {255, 255, 255}, {10, 200, 30}, {200, 16, 90}, {128, 128, 128}};
  cv::Mat image(40, 50, CV_8UC3);
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) image.at<cv::Vec3b>(y, x) = colours[(x / 10 + y / 8) % colours.size()];
  }
  const MedianCutPalette palette = MedianCutPalette::Build(image, 255, 1);
  EXPECT_EQ(palette.colours().size(), colours.size());
  EXPECT_EQ(palette.MeanSquaredError(image, 1), 0.0);
  cv::Mat indices;
  palette.Map(image, /*dither=*/false, &indices);
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) {
      ASSERT_EQ(palette.colours()[indices.at<uint8_t>(y, x)], image.at<cv::Vec3b>(y, x)) << x << "," << y;
    }
  }
}

TEST(MedianCutPaletteTest, AGradientIsApproximatedClosely) {
  cv::Mat image(64, 256, CV_8UC3);
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) image.at<cv::Vec3b>(y, x) = cv::Vec3b(x, 255 - x, (x + 4 * y) % 256);
  }
  const MedianCutPalette palette = MedianCutPalette::Build(image, 255, 1);
  EXPECT_LE(palette.colours().size(), 255u);
  // 255 entries over a 2D colour manifold: a few levels of error, far below a 16-colour palette.
  const double error = palette.MeanSquaredError(image, 1);
  const double coarse = MedianCutPalette::Build(image, 16, 1).MeanSquaredError(image, 1);
  EXPECT_LT(error, 30.0);
  EXPECT_LT(error * 4, coarse);
}

TEST(MedianCutPaletteTest, DitheringKeepsTheLocalMeanOfAColourBetweenEntries) {
  // Two flat halves give a two-entry palette; a third colour half-way between them maps to one
  // entry without dithering, and to a mix whose mean is near the true colour with it.
  cv::Mat build(8, 16, CV_8UC3, cv::Scalar(60, 60, 60));
  build(cv::Rect(8, 0, 8, 8)).setTo(cv::Scalar(76, 76, 76));
  const MedianCutPalette palette = MedianCutPalette::Build(build, 2, 1);
  ASSERT_EQ(palette.colours().size(), 2u);
  const cv::Mat middle(32, 32, CV_8UC3, cv::Scalar(67, 67, 67));
  cv::Mat plain;
  cv::Mat dithered;
  palette.Map(middle, false, &plain);
  palette.Map(middle, true, &dithered);
  auto mean_level = [&](const cv::Mat& indices) {
    double sum = 0;
    for (int y = 0; y < indices.rows; ++y) {
      for (int x = 0; x < indices.cols; ++x) sum += palette.colours()[indices.at<uint8_t>(y, x)][0];
    }
    return sum / indices.total();
  };
  std::set<int> used(dithered.begin<uint8_t>(), dithered.end<uint8_t>());
  EXPECT_EQ(used.size(), 2u);
  EXPECT_GT(std::abs(mean_level(plain) - 67.0), 6.0);
  EXPECT_LT(std::abs(mean_level(dithered) - 67.0), 2.5);
}

}  // namespace
}  // namespace px::clip
