// Holes at the frame's border: the parts of a view that no source saw (a camera turned or backed
// away past the rig). Nothing beyond them is known, so they are filled by carrying the known pixels
// at their inner edge straight out to the border, averaged along it over a width that grows with
// the distance carried: edges that cross the border (a floor line, a box's side) go on, and the
// fill fades to the local mean where a guess is least likely to be right (ALGORITHM.md section 6).
#pragma once

#include <opencv2/core.hpp>

namespace px::render {

// Which sides of an image are the frame's own border (a box inside the frame has fewer).
struct FrameSides {
  bool left = true, top = true, right = true, bottom = true;
};

// The sides of `box` that lie on the border of a frame of `frame_size`.
FrameSides SidesOnFrameBorder(const cv::Rect& box, const cv::Size& frame_size);

struct BorderHoleFillOptions {
  // false: border holes go to the reverse soft z's ring-by-ring smear like any other.
  bool enabled = true;
  // Half-width of the average along the border (triangle weights), per pixel of distance carried:
  // 0 copies the edge pixel straight out.
  float spread = 0.5f;
};

// Fills the unknown pixels (known == 0) of the 8-connected holes that touch a side in `sides`:
// each from the known pixels met going straight in from that side (the nearest such side the hole
// touches), averaged over the lines within spread * distance beside it. Colour (CV_32FC3) and depth
// (CV_32F) alike; filled pixels become 255 in `known`. Other holes, and pixels whose line in meets
// nothing known, are left. Returns the pixels filled.
int FillBorderHoles(
    const FrameSides& sides, const BorderHoleFillOptions& options, cv::Mat* known, cv::Mat* colour, cv::Mat* depth);

}  // namespace px::render
