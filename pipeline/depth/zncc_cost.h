// Windowed matching cost for the plane sweep: 1 - ZNCC (zero-mean normalised cross-correlation)
// of grey values over a (2r+1)^2 box window. ZNCC ignores gain and offset between lenses
// (vignetting, exposure). Window sums are separable: direct sums along rows, running sums down
// columns, all in plain loops the compiler vectorises.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace px::depth {

// Costs lie in [0, 2]: 0 = perfect match, 1 = uncorrelated (also what a textureless reference
// window gets), 2 = inverted. kNoDataCost marks "no valid sample" after aggregation.
constexpr float kNeutralCost = 1.0f;
constexpr float kNoDataCost = 2.0f;
// Written where a sample is invalid (outside the source view); above every real cost.
constexpr float kInvalidCost = 1e9f;

// Window statistics of a reference image, computed once per reference view.
struct ReferenceWindows {
  int radius_px = 0;
  float min_variance = 0;  // windows below it count as textureless
  cv::Mat gray;            // CV_32F in [0, 1]
  cv::Mat mean;            // CV_32F window mean of gray
  cv::Mat inv_stddev;      // CV_32F 1 / stddev of the window, 0 where textureless
};

// Needs an image of at least 1x1; windows reflect at the borders (OpenCV's BORDER_REFLECT).
ReferenceWindows PrepareReferenceWindows(const cv::Mat& gray, int radius_px, double min_texture_stddev);

// Buffers reused between calls (one per thread).
struct ZnccWorkspace {
  cv::Mat row_sums;             // CV_32F, 3 * rows x cols: window-row sums of w, w^2, ref * w
  std::vector<float> products;  // w^2 and ref * w of one row
  std::vector<float> padded;
  std::vector<float> column_sums;
};

// Cost of matching `ref` against `warped` (the source view warped into the reference view,
// CV_32F, same size) into `cost` (CV_32F). Where `valid` (CV_8U, optional) is 0 the cost is
// kInvalidCost. A warped window flatter than min_variance is treated as having min_variance, so
// matching texture against a flat patch costs about kNeutralCost instead of dividing by zero.
void ComputeZnccCost(
    const ReferenceWindows& ref, const cv::Mat& warped, const cv::Mat& valid, ZnccWorkspace* workspace, cv::Mat* cost);

}  // namespace px::depth
