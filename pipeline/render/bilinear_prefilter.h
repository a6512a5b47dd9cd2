// Segment colours sharpened once per scene so that bilinear sampling does not blur them (ALGORITHM.md
// section 1): a bilinear fetch between texel centres averages neighbours (at a half-pixel offset,
// [1/2 1/2] per axis), and the sources are already pixel-area averages, so a novel view between
// lenses comes out softer than the truth at every texture edge and silhouette. A small Laplacian
// boost within each segment (never across a segment's border) restores the mean frequency
// response; both back ends sample these colours, so they stay in agreement. The boost stops at
// depth edges, not at segment borders: a neighbour of another segment whose plane continues the
// pixel's surface counts (the segmentation cuts flat surfaces into many segments, and a boost cut
// at each of their borders left a soft line along every one of them).

#pragma once

#include <array>
#include <opencv2/core.hpp>

#include "pipeline/core/layered_depth.h"

namespace px::render {

// Boost per 4-neighbour of the same segment: c' = c + kBilinearSharpen * sum (c - c_n), clamped
// to [0, 255]. A bilinear fetch at offset t spreads a texel with variance t (1 - t) per axis, 1/6
// on average over t; [-a, 1 + 2a, -a] takes 2a away, so a = 1/12 makes the mean spread zero (an
// integer offset is then over-sharpened by as much as a half-pixel one is blurred). Measured on
// the simulated scenes with exact depth (`parallax eval render --depth truth`): 1/12 36.58 dB,
// 1/8 36.48 dB, none 36.14 dB (pipeline/render/README.md).
constexpr float kBilinearSharpen = 1.0f / 12;

// A neighbour of another segment is on the same surface when that segment's plane there lies
// within this fraction of the pixel's own segment's inverse depth. Measured on the simulated
// scenes with the depth stage (`parallax eval render --depth stage`): 0.002, 0.005 and 0.02 all
// 37.76 dB against 37.57 with the boost cut at every segment border; 1 (across depth edges too)
// 37.75, and worse with exact depth and on HCI.
constexpr double kSameSurfaceTolerance = 0.005;

// Both layers' colours of `view`, sharpened (CV_8UC3 each; texels of weight 0 unchanged). Planes
// at or behind infinity at a pixel continue no surface there.
std::array<cv::Mat, 2> PrefilterForBilinear(const LayeredDepthView& view, float sharpen = kBilinearSharpen);

}  // namespace px::render
