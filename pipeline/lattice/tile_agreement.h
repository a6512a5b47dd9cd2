// Whether a grid's tiles show one scene: neighbouring lenses see the same structure, shifted by
// parallax, while a cut through one picture (a dark band of content taken for a gap) gives tiles of
// different parts of the scene. Blind lattice detection (lattice_detector.h) uses it to choose
// between the counts an ambiguous period fits, to refuse gaps whose tiles disagree, and to cut
// abutting views into equal tiles.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace px::lattice {

// Tiles whose agreement reaches this show one scene. Measured (pipeline/lattice/README.md): the
// real lattice frames' tiles 0.81 to 0.92 and the simulated lattices' at least 0.75, against at
// most 0.29 for any cut of 25 real single photos into equal tiles.
constexpr double kSameSceneAgreement = 0.5;

// TileAgreement of tiles too thin to compare (under 8 working pixels after the trim).
constexpr double kTilesTooThin = -2.0;

// The smallest, over pairs of neighbouring tiles, of how alike their pictures are: the normalised
// cross-correlation of their derivatives across and along the rows, the worse of the two, at the
// best shift of up to a sixth of a tile (parallax). Tiles lie between the gaps (working pixels of
// `grey`, CV_32F), each trimmed by a tenth of its size off every side so that no gap or dark rim
// enters. [-1, 1]; 1 for a single tile; kTilesTooThin. Stops at the first pair below
// `stop_below` and returns the smallest figure so far (then an upper bound of the whole figure).
double TileAgreement(const cv::Mat& grey,
                     const std::vector<double>& x_gaps,
                     const std::vector<double>& y_gaps,
                     double stop_below = -1.0);

// The frame the coarse search reads: at most `working_size_px` on its longer side, float, lightly
// blurred. `grey` is CV_8UC1.
cv::Mat CoarseWorkingFrame(const cv::Mat& grey, int working_size_px);

// A cut of a frame into rows x cols equal tiles.
struct EqualCut {
  int rows = 0, cols = 0;  // 0 when no cut's tiles show one scene
  double agreement = -1;   // the cut's; without one, the best of all cuts' (when measured fully)
  int tried = 0;           // cuts that fit the limits below
};

// Tiles of a lattice cut without gaps are at most this many times longer than wide.
constexpr double kMaxEqualTileAspect = 3.0;

// The cut of `grey` (working pixels, CV_32F) into the most equal tiles whose agreement reaches
// kSameSceneAgreement. It refines `found` (the lattice the gaps gave, 1x1 for none): more tiles,
// in whole multiples of its rows and columns (at least 1), at most `max_per_axis` along either axis (exactly
// `rows` or `cols` where given, > 0), each at most kMaxEqualTileAspect times longer than wide.
// Unless `measure_fully`, a cut is dropped at its first pair of tiles that disagree.
EqualCut FindEqualCut(
    const cv::Mat& grey, cv::Size found, int max_per_axis, int rows = 0, int cols = 0, bool measure_fully = false);

}  // namespace px::lattice
