// Coarse evidence for the straight lines that separate tiles: for every position along one axis
// of a (downscaled) frame, how strongly a line running across the whole frame at that position
// stands out as a gap (a dark or bright band) or a tile edge. Lines may be sheared slightly (a
// frame scanned askew); content rarely forms a line that crosses the frame from side to side.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

namespace px::lattice {

struct BoundaryProfile {
  // Per position x along the axis:
  std::vector<float> strength;     // |band response|, grey levels: the line against its two sides
  std::vector<float> z;            // strength as a robust z-score against the profile at the same width
  std::vector<int8_t> polarity;    // -1: darker than both sides (dark gap), +1: brighter (bright gap)
  std::vector<int8_t> half_width;  // band half-width that responded most, working pixels
  std::vector<float> level;        // grey level along the line (median across the frame)
  double shear = 0;                // dx/dy of the lines that respond most overall (a tilted frame)
  double background_median = 0;    // of strength at the last width that won somewhere, for messages
  double background_sigma = 0;     // its robust standard deviation

  int size() const { return static_cast<int>(strength.size()); }
  int ArgMaxZ(int begin, int end) const;  // position of the largest z in [begin, end)
};

// Evidence for lines running along y (vertical lines at each x) in `grey` (CV_32F, one channel).
// The frame is cut into horizontal strips; each strip gives a column profile (medians), band
// responses at several widths are taken in each strip, and the median across strips (after a
// shear of at most max_rotation_deg) keeps only what most of the frame's height agrees on.
BoundaryProfile VerticalBoundaryProfile(const cv::Mat& grey, double max_rotation_deg);

}  // namespace px::lattice
