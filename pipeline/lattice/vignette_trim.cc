#include "pipeline/lattice/vignette_trim.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace px::lattice {
namespace {

// Profiles are read off the tile reduced to at most this many pixels a side.
constexpr int kProfileSidePx = 256;
constexpr double kBrightPercentile = 0.9;
// A side is trimmed at most this many times as far as the side opposite it.
constexpr int kMaxSideRatio = 2;

// Per column of `image` (CV_8UC1), the kBrightPercentile of its values.
std::vector<double> BrightColumns(const cv::Mat& image) {
  std::vector<double> profile(image.cols);
  std::vector<uint8_t> column(image.rows);
  const size_t rank = static_cast<size_t>(kBrightPercentile * (image.rows - 1));
  for (int x = 0; x < image.cols; ++x) {
    for (int y = 0; y < image.rows; ++y) column[y] = image.at<uint8_t>(y, x);
    std::nth_element(column.begin(), column.begin() + rank, column.end());
    profile[x] = column[rank];
  }
  return profile;
}

// How many entries from the front and from the back of `profile` lie below kLitShare of its
// central half's median, counted inward, each at most kMaxTrimPerSide of it. The median, not the
// brightest: a bright highlight (water, sky) would make the scene's shadows look vignetted.
std::pair<int, int> DarkEnds(const std::vector<double>& profile) {
  const int n = static_cast<int>(profile.size());
  std::vector<double> centre(profile.begin() + n / 4, profile.begin() + (3 * n) / 4);
  if (centre.empty()) return {0, 0};
  std::nth_element(centre.begin(), centre.begin() + centre.size() / 2, centre.end());
  const double lit = kLitShare * centre[centre.size() / 2];
  const int most = static_cast<int>(kMaxTrimPerSide * n);
  int front = 0, back = 0;
  while (front < most && profile[front] < lit) ++front;
  while (back < most && profile[n - 1 - back] < lit) ++back;
  return {front, back};
}

}  // namespace

std::array<int, 4> VignettedBorder(const cv::Mat& grey, const cv::Rect& tile) {
  const cv::Rect inside = tile & cv::Rect(0, 0, grey.cols, grey.rows);
  if (inside.width < 8 || inside.height < 8) return {0, 0, 0, 0};
  // Each axis reduced to at most kProfileSidePx (and at least 1) pixels.
  const cv::Size reduced(std::clamp(inside.width, 1, kProfileSidePx), std::clamp(inside.height, 1, kProfileSidePx));
  cv::Mat small;
  cv::resize(grey(inside), small, reduced, 0, 0, cv::INTER_AREA);
  const auto [left, right] = DarkEnds(BrightColumns(small));
  const auto [top, bottom] = DarkEnds(BrightColumns(small.t()));
  // Back to the frame's pixels, rounded inward, within kMaxTrimPerSide of the tile.
  const auto full = [](int n, int reduced_px, int tile_px) {
    const int most = static_cast<int>(kMaxTrimPerSide * tile_px);
    return std::min(most, static_cast<int>(std::ceil(static_cast<double>(n) * tile_px / reduced_px)));
  };
  return {full(left, small.cols, inside.width),
          full(right, small.cols, inside.width),
          full(top, small.rows, inside.height),
          full(bottom, small.rows, inside.height)};
}

std::vector<cv::Rect> LitTiles(const cv::Mat& grey, const std::vector<cv::Rect>& tiles) {
  if (tiles.empty()) return {};
  std::array<std::vector<int>, 4> per_side;
  int width = tiles.front().width, height = tiles.front().height;
  for (const cv::Rect& tile : tiles) {
    const std::array<int, 4> border = VignettedBorder(grey, tile);
    for (int side = 0; side < 4; ++side) per_side[side].push_back(border[side]);
    width = std::min(width, tile.width);
    height = std::min(height, tile.height);
  }
  std::array<int, 4> median;
  for (int side = 0; side < 4; ++side) {
    std::vector<int>& values = per_side[side];
    const size_t lower_median = (values.size() - 1) / 2;
    std::nth_element(values.begin(), values.begin() + lower_median, values.end());
    median[side] = values[lower_median];
  }
  // A lens's vignette darkens opposite sides alike (within kMaxSideRatio); a dark part of the
  // scene along one side (the ground, a shadow), which every tile of one scene shows, does not.
  std::array<int, 4> trim;
  for (int side = 0; side < 4; ++side) trim[side] = std::min(median[side], kMaxSideRatio * median[side ^ 1]);
  width = std::max(1, width - trim[0] - trim[1]);
  height = std::max(1, height - trim[2] - trim[3]);
  std::vector<cv::Rect> lit;
  for (const cv::Rect& tile : tiles) lit.emplace_back(tile.x + trim[0], tile.y + trim[2], width, height);
  return lit;
}

}  // namespace px::lattice
