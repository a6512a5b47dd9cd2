// Options for finding the tile lattice on a raw multi-lens sensor frame (lattice_detector.h).
#pragma once

#include "pipeline/core/lattice_layout.h"
#include "pipeline/core/status.h"

namespace px {

struct LatticeOptions {
  // Expected lattice size; 0 = find it (2x2, 3x3, 5x4, ... up to max_tiles_per_axis). With a
  // prior layout the prior's size is used and these must be 0 or agree with it.
  int rows = 0;  // [0, max_tiles_per_axis]
  int cols = 0;  // [0, max_tiles_per_axis]
  // Largest count searched along either axis, [2, 16]. Finer periodic structure (a micro-lens
  // array) is refused rather than taken for a lattice.
  int max_tiles_per_axis = 8;
  // Largest tilt of a tile the search allows for, degrees, [0, 10].
  double max_rotation_deg = 3.0;
  // Tiles whose width or height differ from the median by more than this fraction are refused
  // as "wildly different sizes", (0, 1].
  double max_size_spread = 0.25;
  // A gap must stand out from the frame's background profile by this many robust standard
  // deviations (z-score) to count, [2, 50].
  double min_gap_z = 6.0;
  // With a prior layout: how far from the prior's tile edges to look, sensor pixels, [2, 200].
  double prior_search_px = 12.0;
  // Detections less certain than this are refused, [0, 1]: confidence is the fraction of edge
  // cuts that found their edge, times (blind search) the weakest gap's evidence against
  // 2 x min_gap_z, capped at 1. Real lattices score above 0.9; content lines taken for a lattice
  // score about 0.3.
  double min_confidence = 0.5;
  // How tiles lie when no prior says: kRotated180 = each lens inverts its image (the simulated
  // cameras, film scans read without their EXIF rotation). Detection cannot tell orientations apart.
  TileOrientation orientation = TileOrientation::kRotated180;
  // The coarse search runs on a copy whose longer side is at most this, pixels, [256, 4096].
  int working_size_px = 1024;

  Status Validate() const;
};

}  // namespace px
