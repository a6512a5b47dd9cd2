// The depth and disparity error measures of `parallax eval depth`, each as its benchmark
// defines it. Estimates and ground truth are CV_32F maps of the same size.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>

namespace px::eval {

// HCI 4D light field benchmark (Honauer et al. 2016, evaluation toolkit): over the image minus a
// `boundary_px` frame (15 px at 512x512), BadPix(t) = % of pixels with |d - gt| > t and
// MSE x 100 = 100 * mean((d - gt)^2). Non-finite estimates count as bad and are left out of MSE.
struct HciMetrics {
  double bad_pix_007 = 0;  // %
  double bad_pix_003 = 0;  // %
  double mse_x100 = 0;
  int64_t pixels = 0;
};
HciMetrics EvaluateHciDisparity(const cv::Mat& disparity, const cv::Mat& gt_disparity, int boundary_px = 15);

// Two-view stereo (Middlebury, ETH3D): over every pixel with finite ground truth, bad-t = % of
// pixels with |d - gt| > t px, and the mean |d - gt|. A pixel without an estimate (non-finite)
// counts as bad, with an error of its ground-truth disparity (what an estimate of 0 would score).
struct StereoMetrics {
  double bad_1 = 0;      // %
  double bad_2 = 0;      // %
  double avg_error = 0;  // px
  int64_t pixels = 0;
};
StereoMetrics EvaluateStereoDisparity(const cv::Mat& disparity, const cv::Mat& gt_disparity);

// Simulated scenes with exact depth: over pixels with gt > 0, the median of |z - gt| / gt and
// the % of pixels off by more than 5 %; the same within edge_radius_px of a depth edge (a jump
// of more than 5 % between 4-neighbours of the ground truth, or a pixel that hits nothing).
struct DepthErrorMetrics {
  double median_relative = 0;  // fraction
  double bad_5_percent = 0;    // %
  double edge_median_relative = 0;
  double edge_bad_5_percent = 0;
  int64_t pixels = 0;
  int64_t edge_pixels = 0;
};
DepthErrorMetrics EvaluateDepth(const cv::Mat& depth_m, const cv::Mat& gt_depth_m, int edge_radius_px = 3);

// 255 within radius_px of a depth edge of `gt_depth_m` (see EvaluateDepth), else 0.
cv::Mat DepthEdgeMask(const cv::Mat& gt_depth_m, int radius_px);

}  // namespace px::eval
