// Stage 1, when the layout is not known (or not trusted): find the tile lattice on one raw
// multi-lens sensor frame. Tiles are told apart by the gaps between them (dark or bright bands),
// vignetting falling off towards their borders and their straight edges; they may be slightly
// turned, unequal in size and offset. A coarse search on a downscaled copy finds how many tiles
// lie along each axis and roughly where the gaps are; each tile's four edges are then fitted as
// lines on the full frame, which gives its rectangle and rotation to a fraction of a pixel.
// With a prior layout (the rig calibration's) the coarse search is skipped: edges are looked for
// near the prior's and the shift is reported.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "pipeline/core/lattice_layout.h"
#include "pipeline/core/status.h"
#include "pipeline/lattice/lattice_options.h"

namespace px {

struct DetectedTile {
  int row = 0;
  int col = 0;
  cv::Rect rect;               // as in Tile: the unrotated rectangle, sensor pixels
  double rotation_deg = 0;     // as in Tile
  int edges_fitted = 0;        // of 4; an edge on the frame's border counts as fitted
  double edge_rms_px = 0;      // residual of the edge points about their lines (fitted edges)
  double inlier_fraction = 0;  // of the cuts across its searched edges that found the edge, [0, 1]
  cv::Point2d shift_px;        // centre minus the prior's centre (0 without a prior)
};

struct LatticeReport {
  int rows = 0;
  int cols = 0;
  std::vector<DetectedTile> tiles;    // row-major, as the layout's
  double confidence = 0;              // [0, 1]: edges found and gap evidence, 1 = all clear
  std::vector<std::string> evidence;  // what told the tiles apart, with figures
  double weakest_gap_z = 0;           // coarse evidence of the weakest gap (blind search only)
  // How alike neighbouring tiles' pictures are (tile_agreement.h), measured where the lattice's
  // size was not given (blind search only); -1 when not measured.
  double tile_agreement = -1;
  bool used_prior = false;
  double max_prior_shift_px = 0;  // largest |shift_px| over the tiles
  double ms = 0;                  // time taken

  std::string Summary() const;  // one line: "3x3, confidence 0.97, dark gaps ..., 31 ms"
};

struct LatticeDetection {
  LatticeLayout layout;  // valid; tiles in options.orientation (or the prior's orientations)
  LatticeReport report;
};

// Finds the lattice on `sensor_bgr` (CV_8UC3 or CV_8UC1, at least 32x32). With `prior`, rows,
// cols and orientations come from it (scaled if the frame's size differs in proportion) and
// edges are searched within options.prior_search_px of its tiles. Errors: INVALID_ARGUMENT for
// bad options, an empty or wrongly typed frame, a prior of another aspect ratio; NOT_FOUND, with
// the reason, when no lattice can be found (a blank frame, no gaps, an ambiguous period, a
// micro-lens image, tiles of wildly different sizes, edges that fit no tile, a frame that does
// not show the prior's lattice, a confidence below options.min_confidence, tiles whose pictures do
// not show one scene when the size was not given). Blind, with both options.rows and options.cols
// given, a frame whose gaps cannot be found, and that shows no lattice of another size either, is
// cut into equal tiles (abutting tiles, as a wiggle lens's), confidence 0, the evidence saying so.
// Without the size, such a frame is cut into the most equal tiles whose pictures show one scene,
// and so are tiles found more than twice as long as wide (several abutting views), along their
// length. The tiles of such an even cut are then cut down to what their lenses lit
// (vignette_trim.h), so they no longer cover the frame.
StatusOr<LatticeDetection> DetectLattice(const cv::Mat& sensor_bgr,
                                         const LatticeOptions& options,
                                         const LatticeLayout* prior = nullptr);

}  // namespace px
