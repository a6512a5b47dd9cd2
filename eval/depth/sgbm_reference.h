// The evaluation's two-view reference: OpenCV's StereoSGBM (semi-global block matching,
// Hirschmueller 2008) on a rectified pair, with the settings OpenCV's own stereo sample
// recommends, and its invalid pixels (occlusions, failed uniqueness or left-right checks) filled
// along each row from the farther valid neighbour, as the Middlebury evaluation fills sparse
// results, so that it is scored on a dense map like the other methods.
#pragma once

#include <opencv2/core.hpp>

namespace px::eval {

struct SgbmResult {
  cv::Mat disparity;          // CV_32F of the left image's size: x_right = x_left - d
  double valid_fraction = 0;  // of pixels SGBM itself gave a disparity (before filling)
};

// left, right: CV_8UC3 rectified images of equal size. The search covers [min_disparity,
// max_disparity] px (either may be negative; widened to OpenCV's multiple of 16).
SgbmResult RunSgbm(const cv::Mat& left, const cv::Mat& right, double min_disparity, double max_disparity);

// SGBM with the pair swapped left-right: disparity of `right` measured against `left`, i.e. for
// a reference view whose partner lies to its left (x_left = x_right + d, d >= 0 in front).
SgbmResult RunSgbmRightReference(const cv::Mat& left, const cv::Mat& right, double min_disparity, double max_disparity);

}  // namespace px::eval
