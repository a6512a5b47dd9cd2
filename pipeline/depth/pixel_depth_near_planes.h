// The layered view's plain depth map keeps the matcher's own per-pixel depth where it stays near
// the segment's plane. A segment's plane is a fit to its pixels: it fills in occlusions and
// mismatches, but flattens curved and steeply slanted surfaces (the HCI statue and floor) and
// fine relief, which the per-pixel estimate keeps. Pixels far off their plane are the matcher's
// outliers (occlusions, repeated texture) and take the plane. The segments and their planes
// (what the renderer draws) are untouched; so are the two-layer bands, whose depth is the layer
// they show.
#pragma once

#include <opencv2/core.hpp>

#include "pipeline/core/layered_depth.h"

namespace px::depth {

// view->depth_m becomes 1 / inverse_depth (CV_32F, the view's size, 1/m) wherever that inverse
// depth is positive and within max_difference (1/m) of the plane's (1 / depth_m), and the pixel
// is covered by layer 0 alone (no second segment: outside the two-layer bands). Returns how many pixels changed.
int KeepPixelDepthNearPlanes(const cv::Mat& inverse_depth, double max_difference, LayeredDepthView* view);

}  // namespace px::depth
