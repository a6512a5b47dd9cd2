#include "eval/depth/sgbm_reference.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/calib3d.hpp>

namespace px::eval {
namespace {

// Fills each row's invalid runs with the smaller (farther) of the valid disparities at their two
// ends, or the one that exists.
void FillRowsFromBackground(cv::Mat* disparity) {
  for (int y = 0; y < disparity->rows; ++y) {
    float* d = disparity->ptr<float>(y);
    int x = 0;
    while (x < disparity->cols) {
      if (std::isfinite(d[x])) {
        ++x;
        continue;
      }
      const int start = x;
      while (x < disparity->cols && !std::isfinite(d[x])) ++x;
      const float left = start > 0 ? d[start - 1] : std::numeric_limits<float>::quiet_NaN();
      const float right = x < disparity->cols ? d[x] : std::numeric_limits<float>::quiet_NaN();
      float fill =
          std::isfinite(left) && std::isfinite(right) ? std::min(left, right) : (std::isfinite(left) ? left : right);
      for (int i = start; i < x; ++i) d[i] = fill;
    }
  }
}

}  // namespace

SgbmResult RunSgbm(const cv::Mat& left, const cv::Mat& right, double min_disparity, double max_disparity) {
  const int min_d = static_cast<int>(std::floor(min_disparity));
  const int count = std::max(16, (static_cast<int>(std::ceil(max_disparity - min_d)) + 1 + 15) / 16 * 16);
  constexpr int kBlock = 5;  // OpenCV's stereo_match sample: 3..11 odd; P1, P2 as it sets them
  const int channels = left.channels();
  cv::Ptr<cv::StereoSGBM> sgbm = cv::StereoSGBM::create(min_d,
                                                        count,
                                                        kBlock,
                                                        8 * channels * kBlock * kBlock,
                                                        32 * channels * kBlock * kBlock,
                                                        /*disp12MaxDiff=*/1,
                                                        /*preFilterCap=*/63,
                                                        /*uniquenessRatio=*/10,
                                                        /*speckleWindowSize=*/100,
                                                        /*speckleRange=*/32,
                                                        cv::StereoSGBM::MODE_HH);
  cv::Mat fixed;
  sgbm->compute(left, right, fixed);  // CV_16S, 4 fractional bits; (min_d - 1) * 16 where invalid
  SgbmResult result;
  result.disparity.create(left.size(), CV_32F);
  int64_t valid = 0;
  for (int y = 0; y < fixed.rows; ++y) {
    const int16_t* f = fixed.ptr<int16_t>(y);
    float* d = result.disparity.ptr<float>(y);
    for (int x = 0; x < fixed.cols; ++x) {
      const bool ok = f[x] >= min_d * 16;
      d[x] = ok ? f[x] / 16.0f : std::numeric_limits<float>::quiet_NaN();
      valid += ok ? 1 : 0;
    }
  }
  result.valid_fraction = static_cast<double>(valid) / static_cast<double>(fixed.total());
  FillRowsFromBackground(&result.disparity);
  return result;
}

SgbmResult RunSgbmRightReference(const cv::Mat& left,
                                 const cv::Mat& right,
                                 double min_disparity,
                                 double max_disparity) {
  // Mirroring both images turns the right view into a left view of the mirrored pair.
  cv::Mat left_mirrored, right_mirrored;
  cv::flip(left, left_mirrored, 1);
  cv::flip(right, right_mirrored, 1);
  SgbmResult result = RunSgbm(right_mirrored, left_mirrored, min_disparity, max_disparity);
  cv::flip(result.disparity, result.disparity, 1);
  return result;
}

}  // namespace px::eval
