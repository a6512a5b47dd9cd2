// Where the holes of a frame are, as a few boxes, so that the per-hole work (hole filling, H(V))
// runs on those boxes instead of the whole frame. A frame usually has holes along one or two of
// its borders and behind a few silhouettes: a fraction of a percent of its pixels.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace px::render {

// Boxes holding every hole (coverage == 0) of `coverage` (CV_8U), each grown by `margin_px` and
// clipped to the frame; the holes of one box lie more than `margin_px` away from every other box's
// holes. Every pixel outside the boxes' holes within `margin_px` of them is covered, so an
// operation whose reach from a hole is at most `margin_px` (a (2 margin + 1)^2 window, a distance
// transform's mask) gives, box by box, the same result as on the whole frame. Empty when nothing
// is a hole. The boxes come from the columns with holes split at gaps of more than `margin_px`
// hole-free columns, then each such band's rows split likewise.
std::vector<cv::Rect> HoleRegions(const cv::Mat& coverage, int margin_px);

}  // namespace px::render
