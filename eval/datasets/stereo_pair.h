// A rectified two-view stereo pair with the left view's ground-truth disparity, as the
// Middlebury and ETH3D two-view sets ship them (../shared/data, SOURCES.md 3-5). Convention:
// x_right = x_left - d, with d > 0 for points in front of both cameras at finite depth.
#pragma once

#include <opencv2/core.hpp>
#include <string>

#include "pipeline/core/view.h"

namespace px::eval {

struct StereoPair {
  std::string name;  // "middlebury2003/cones"
  // Pinhole views (ids 0 and 1) with identical intrinsics, left at the world origin and right
  // baseline_m along +x, parallel optical axes: depth z = focal_px * baseline_m / d.
  View left;
  View right;
  double focal_px = 0;
  double baseline_m = 0;  // arbitrary but consistent where the set gives no calibration
  cv::Mat gt_disparity;   // CV_32F, left view's size; NaN where unknown
  // The disparity search range every method gets, in pixels: [min, max], 0 < min < max. From
  // the set's documented disparity count (its `ndisp`), not from the ground truth.
  double min_disparity = 0;
  double max_disparity = 0;

  double DepthFromDisparity(double d) const { return focal_px * baseline_m / d; }
  double DisparityFromDepth(double z) const { return focal_px * baseline_m / z; }
};

// The pair's views from two rectified images of equal size: principal point (cx, cy), focal
// focal_px, the right camera baseline_m to the right of the left one.
StereoPair MakeRectifiedPair(std::string name,
                             const cv::Mat& left_bgr,
                             const cv::Mat& right_bgr,
                             double focal_px,
                             double cx,
                             double cy,
                             double baseline_m);

}  // namespace px::eval
