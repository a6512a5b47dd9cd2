// Tiles cut evenly from abutting sub-images lose their lenses' dark, vignetted borders, and only
// those: not a dark part of the scene at one tile's side or along one side of every tile, not a
// scene that is dark all over.
#include "pipeline/lattice/vignette_trim.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

namespace px::lattice {
namespace {

constexpr int kTiles = 3;

// Three abutting tiles of width x height showing one textured scene (mean grey `level`), tile t
// darkened towards its left and right borders to `floor` over the outer ramps[t] of its width
// (0: not vignetted).
cv::Mat AbuttingTiles(int width, int height, double level, std::array<double, kTiles> ramps, double floor) {
  cv::Mat scene(height, width, CV_32F);
  cv::RNG(3).fill(scene, cv::RNG::UNIFORM, level - 40, level + 40);
  cv::GaussianBlur(scene, scene, cv::Size(0, 0), 1.5);
  cv::Mat frame(height, kTiles * width, CV_8U);
  for (int t = 0; t < kTiles; ++t) {
    cv::Mat tile = scene.clone();
    for (int x = 0; x < width && ramps[t] > 0; ++x) {
      const double from_border = std::min(x, width - 1 - x);
      tile.col(x) *= std::clamp(from_border / (ramps[t] * width), floor, 1.0);
    }
    tile.convertTo(frame(cv::Rect(t * width, 0, width, height)), CV_8U);
  }
  return frame;
}

std::vector<cv::Rect> EvenCut(int width, int height) {
  std::vector<cv::Rect> tiles;
  for (int t = 0; t < kTiles; ++t) tiles.emplace_back(t * width, 0, width, height);
  return tiles;
}

TEST(VignetteTrimTest, AVignettedBorderIsTrimmedFromEveryTileAlike) {
  // Light falls to 15% at the borders over the outer 15% of the width: below half within 7.5 %
  // of it. Small tiles (profiles read as they are) and large ones (profiles of a reduced copy).
  for (const cv::Size size : {cv::Size(200, 150), cv::Size(800, 600)}) {
    const cv::Mat frame = AbuttingTiles(size.width, size.height, 150, {0.15, 0.15, 0.15}, 0.15);
    const std::vector<cv::Rect> lit = LitTiles(frame, EvenCut(size.width, size.height));
    ASSERT_EQ(lit.size(), 3u);
    const double expected = 0.075 * size.width, tolerance = 0.015 * size.width;
    for (int t = 0; t < kTiles; ++t) {
      SCOPED_TRACE(testing::Message() << size << ", tile " << t);
      EXPECT_NEAR(lit[t].x - t * size.width, expected, tolerance);
      EXPECT_NEAR(lit[t].width, size.width - 2 * expected, 2 * tolerance);
      EXPECT_EQ(lit[t].y, 0) << "not vignetted along y";
      EXPECT_EQ(lit[t].height, size.height);
      EXPECT_EQ(lit[t].size(), lit[0].size());
    }
  }
}

TEST(VignetteTrimTest, TheTilesVignetteAsTheMedianTileDoes) {
  // One tile vignetted over twice as much of its width as the others: all lose what the others do.
  const cv::Mat frame = AbuttingTiles(200, 150, 150, {0.3, 0.15, 0.15}, 0.15);
  EXPECT_GT(VignettedBorder(frame, EvenCut(200, 150)[0])[0], 25);
  const std::vector<cv::Rect> lit = LitTiles(frame, EvenCut(200, 150));
  for (int t = 0; t < kTiles; ++t) EXPECT_NEAR(lit[t].x - t * 200, 15, 3) << "tile " << t;
}

TEST(VignetteTrimTest, ADarkSceneIsNotAVignette) {
  const std::vector<cv::Rect> even = EvenCut(200, 150);
  // Evenly lit tiles: nothing to trim, however dark the scene is all over.
  for (const double level : {150.0, 40.0}) {
    const std::vector<cv::Rect> lit = LitTiles(AbuttingTiles(200, 150, level, {0, 0, 0}, 1), even);
    for (int t = 0; t < kTiles; ++t) EXPECT_EQ(lit[t], even[t]) << "grey " << level << ", tile " << t;
  }
  // A dark object over the left third of one tile only: that tile's side alone is dark.
  cv::Mat frame = AbuttingTiles(200, 150, 150, {0, 0, 0}, 1);
  frame(cv::Rect(200, 0, 200 / 3, 150)).setTo(10);
  EXPECT_GT(VignettedBorder(frame, even[1])[0], 0);
  std::vector<cv::Rect> lit = LitTiles(frame, even);
  for (int t = 0; t < kTiles; ++t) EXPECT_EQ(lit[t], even[t]) << "tile " << t;
  // Dark ground along the bottom of every tile (one scene): the top is lit, so it stays.
  frame = AbuttingTiles(200, 150, 150, {0, 0, 0}, 1);
  for (int t = 0; t < kTiles; ++t) frame(cv::Rect(t * 200, 120, 200, 30)).setTo(10);
  EXPECT_GT(VignettedBorder(frame, even[0])[3], 20);
  lit = LitTiles(frame, even);
  for (int t = 0; t < kTiles; ++t) EXPECT_EQ(lit[t], even[t]) << "tile " << t;
}

TEST(VignetteTrimTest, NoSideLosesMoreThanItsShare) {
  // Light at 5% over the outer 30% of each side of each tile: the trim stops at kMaxTrimPerSide.
  cv::Mat frame = AbuttingTiles(200, 150, 150, {0, 0, 0}, 1);
  const int dark = 3 * 200 / 10;
  for (int t = 0; t < kTiles; ++t) {
    frame(cv::Rect(t * 200, 0, dark, 150)) *= 0.05;
    frame(cv::Rect((t + 1) * 200 - dark, 0, dark, 150)) *= 0.05;
  }
  const std::array<int, 4> border = VignettedBorder(frame, EvenCut(200, 150)[0]);
  EXPECT_EQ(border[0], static_cast<int>(kMaxTrimPerSide * 200));
  EXPECT_EQ(border[1], static_cast<int>(kMaxTrimPerSide * 200));
  // A tile too thin to read is left whole.
  EXPECT_EQ(VignettedBorder(frame, cv::Rect(0, 0, 4, 150)), (std::array<int, 4>{0, 0, 0, 0}));
}

}  // namespace
}  // namespace px::lattice
