// Fits one straight tile edge to sub-pixel precision on the full-resolution frame: in many thin
// cuts across the expected edge, the strongest transition of one sign (dark gap to bright tile,
// or the reverse), then a line robust to cuts where content hid the edge.
#pragma once

#include <opencv2/core.hpp>

namespace px::lattice {

// An edge running roughly along y: x = a + b * y (sensor pixels, pixel centres at integers; the
// edge between pixel columns x0 - 1 and x0 lies at x0 - 0.5).
struct EdgeLine {
  double a = 0;
  double b = 0;
  double XAt(double y) const { return a + b * y; }
};

struct EdgeSearch {
  EdgeLine expected;       // where the edge should be
  double along_begin = 0;  // y range of the cuts
  double along_end = 0;
  double behind_px = 4;     // search from expected.x - behind_px ...
  double ahead_px = 4;      // ... to expected.x + ahead_px
  double max_slope = 0.07;  // |b| allowed (tan of the largest tilt)
  int sign = 0;             // +1: brighter at larger x, -1: darker, 0: try both and keep the better
  bool transposed = false;  // the edge runs along x instead: read "x" as y and "y" as x throughout
  // Where the gap lies: -1 at smaller x (a tile's left/top edge), +1 at larger x, 0 unknown. When
  // known, each cut takes the first strong transition met coming from the gap (at least
  // kFirstOfStrongest of the cut's strongest), not the strongest: a bright object's outline just
  // inside the tile must not be taken for the tile's edge.
  int gap_side = 0;
};

struct EdgeFit {
  bool found = false;
  EdgeLine line;
  int sign = 0;
  int cuts = 0;         // cuts made
  int inliers = 0;      // cuts whose transition lies on the line
  double rms_px = 0;    // of the inliers about the line
  double contrast = 0;  // median |gradient| of the inliers, grey levels per pixel
  double InlierFraction() const { return cuts > 0 ? static_cast<double>(inliers) / cuts : 0.0; }
};

// `grey` is the full frame, CV_8UC1. With search.transposed the edge runs along x and the line
// reads y = a + b * x (the frame is read column-wise; nothing is copied).
EdgeFit FitEdge(const cv::Mat& grey, const EdgeSearch& search);

}  // namespace px::lattice
