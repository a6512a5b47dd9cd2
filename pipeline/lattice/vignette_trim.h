// Sub-images that abut (a wiggle lens on a digital camera, a cheap multi-lens frame) vignette into
// each other: a frame cut evenly into them (lattice_detector.h) gives views whose borders are dark
// falloff, which a clip shows as dark bands moving with the camera. Each such tile is cut down to
// the part its lens lit.
#pragma once

#include <array>
#include <opencv2/core.hpp>
#include <vector>

namespace px::lattice {

// Columns and rows whose bright pixels (their 90th percentile) fall below this share of the
// median of the tile's central half are the vignetted border.
constexpr double kLitShare = 0.5;
// At most this share of a tile is trimmed off any side (a dark scene is not a vignette).
constexpr double kMaxTrimPerSide = 0.2;

// How far `tile` (a rectangle of `grey`, CV_8UC1) is vignetted in from each side: from each side
// inward, the columns or rows darker than kLitShare of the median of its central half, at most
// kMaxTrimPerSide. {left, right, top, bottom}, pixels.
std::array<int, 4> VignettedBorder(const cv::Mat& grey, const cv::Rect& tile);

// The tiles without their lenses' vignetted borders, all of one size: each side trimmed by the
// lower median over the tiles of VignettedBorder there (the vignette is the lenses' own and alike
// in every tile; a dark part of the scene at one tile's side is not), and at most twice as far as
// the side opposite it (a vignette darkens both; the dark ground along the bottom of every tile
// of one scene darkens one).
std::vector<cv::Rect> LitTiles(const cv::Mat& grey, const std::vector<cv::Rect>& tiles);

}  // namespace px::lattice
