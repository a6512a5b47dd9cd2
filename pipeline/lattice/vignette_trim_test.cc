// Tiles cut evenly from abutting sub-images lose their lenses' dark, vignetted borders, and only
// those: not a dark part of the scene at one tile's side, not a scene that is dark all over.
#include "pipeline/lattice/vignette_trim.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

namespace px::lattice {
namespace {

constexpr int kTileWidth = 200, kTileHeight = 150, kTiles = 3;

// Three abutting tiles of one textured scene (mean grey `level`), each darkened towards its left
// and right borders to `floor` over the outer `ramp` of its width (0: not vignetted).
cv::Mat AbuttingTiles(double level, double ramp, double floor) {
  cv::Mat scene(kTileHeight, kTileWidth, CV_32F);
  cv::RNG(3).fill(scene, cv::RNG::UNIFORM, level - 40, level + 40);
  cv::GaussianBlur(scene, scene, cv::Size(0, 0), 1.5);
  cv::Mat frame(kTileHeight, kTiles * kTileWidth, CV_8U);
  for (int t = 0; t < kTiles; ++t) {
    cv::Mat tile = scene.clone();
    for (int x = 0; x < kTileWidth && ramp > 0; ++x) {
      const double from_border = std::min(x, kTileWidth - 1 - x);
      tile.col(x) *= std::clamp(from_border / (ramp * kTileWidth), floor, 1.0);
    }
    tile.convertTo(frame(cv::Rect(t * kTileWidth, 0, kTileWidth, kTileHeight)), CV_8U);
  }
  return frame;
}

std::vector<cv::Rect> EvenCut() {
  std::vector<cv::Rect> tiles;
  for (int t = 0; t < kTiles; ++t) tiles.emplace_back(t * kTileWidth, 0, kTileWidth, kTileHeight);
  return tiles;
}

TEST(VignetteTrimTest, AVignettedBorderIsTrimmedFromEveryTileAlike) {
  // Light falls to 15% at the borders over the outer 15% of the width: below half within 15 px.
  const cv::Mat frame = AbuttingTiles(150, 0.15, 0.15);
  const std::vector<cv::Rect> lit = LitTiles(frame, EvenCut());
  ASSERT_EQ(lit.size(), 3u);
  for (int t = 0; t < kTiles; ++t) {
    EXPECT_NEAR(lit[t].x - t * kTileWidth, 15, 3) << "tile " << t;
    EXPECT_NEAR(lit[t].width, kTileWidth - 30, 5) << "tile " << t;
    EXPECT_EQ(lit[t].y, 0) << "not vignetted along y";
    EXPECT_EQ(lit[t].height, kTileHeight);
    EXPECT_EQ(lit[t].size(), lit[0].size());
  }
}

TEST(VignetteTrimTest, ADarkSceneIsNotAVignette) {
  // Evenly lit tiles: nothing to trim, however dark the scene is all over.
  for (const double level : {150.0, 40.0}) {
    const std::vector<cv::Rect> lit = LitTiles(AbuttingTiles(level, 0, 1), EvenCut());
    for (int t = 0; t < kTiles; ++t) EXPECT_EQ(lit[t], EvenCut()[t]) << "grey " << level << ", tile " << t;
  }
  // A dark object over the left third of one tile only: that tile's side alone is dark.
  cv::Mat frame = AbuttingTiles(150, 0, 1);
  frame(cv::Rect(kTileWidth, 0, kTileWidth / 3, kTileHeight)).setTo(10);
  EXPECT_GT(VignettedBorder(frame, EvenCut()[1])[0], 0);
  const std::vector<cv::Rect> lit = LitTiles(frame, EvenCut());
  for (int t = 0; t < kTiles; ++t) EXPECT_EQ(lit[t], EvenCut()[t]) << "tile " << t;
}

TEST(VignetteTrimTest, NoSideLosesMoreThanItsShare) {
  // Light at 5% over the outer 30% of each side of each tile: the trim stops at kMaxTrimPerSide.
  cv::Mat frame = AbuttingTiles(150, 0, 1);
  const int dark = 3 * kTileWidth / 10;
  for (int t = 0; t < kTiles; ++t) {
    frame(cv::Rect(t * kTileWidth, 0, dark, kTileHeight)) *= 0.05;
    frame(cv::Rect((t + 1) * kTileWidth - dark, 0, dark, kTileHeight)) *= 0.05;
  }
  const std::array<int, 4> border = VignettedBorder(frame, EvenCut()[0]);
  EXPECT_EQ(border[0], static_cast<int>(kMaxTrimPerSide * kTileWidth));
  EXPECT_EQ(border[1], static_cast<int>(kMaxTrimPerSide * kTileWidth));
}

}  // namespace
}  // namespace px::lattice
