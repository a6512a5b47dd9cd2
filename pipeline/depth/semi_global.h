// Semi-global aggregation (Hirschmueller 2008) over a plane-sweep cost volume: each pixel's cost
// curve gets the cheapest path costs arriving from 4 or 8 directions, with a small penalty for a
// step of one plane between neighbouring pixels (slanted and curved surfaces) and a large one for
// bigger jumps, lowered across grey edges of the reference (depth edges follow colour edges). It
// carries evidence from textured pixels across weakly textured ones (walls, floors) that window
// costs alone leave ambiguous.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace px::depth {

struct SemiGlobalOptions {
  int num_paths = 4;           // 4 (rows and columns) or 8 (and diagonals)
  float step_penalty = 0.01f;  // P1: one plane of change to the next pixel, cost units
  float jump_penalty = 0.12f;  // P2: more than one plane, cost units (>= step_penalty)
  // Across a grey step of at least this ([0, 1] units) the jump penalty drops to a third.
  float edge_gray = 0.04f;
};

// The semi-global aggregate of `slices` (one CV_32F cost per plane, all of `gray`'s size, at
// least 2), divided by the number of paths so costs keep their scale; `slices` is left as it is.
// `gray` is the reference image (CV_32F in [0, 1]). Uses two threads (the forward and backward
// sweeps); memory is the returned volume plus a few rows of path costs per thread.
std::vector<cv::Mat> AggregateSemiGlobal(const cv::Mat& gray,
                                         const SemiGlobalOptions& options,
                                         const std::vector<cv::Mat>& slices);

}  // namespace px::depth
