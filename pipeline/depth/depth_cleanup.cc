#include "pipeline/depth/depth_cleanup.h"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/ximgproc/edge_filter.hpp>
#include <vector>

#include "pipeline/core/check.h"

namespace px::depth {

void LowerSpeckleConfidence(
    const cv::Mat& plane, int max_size_px, float max_jump_planes, float confidence_cap, cv::Mat* confidence) {
  if (max_size_px <= 0) return;
  // filterSpeckles works on 16-bit fixed point; 16 steps per plane keeps the sub-plane part.
  constexpr float kSteps = 16;
  constexpr int16_t kMarker = -1;
  cv::Mat fixed;
  plane.convertTo(fixed, CV_16S, kSteps);
  cv::filterSpeckles(fixed, kMarker, max_size_px, max_jump_planes * kSteps);
  for (int y = 0; y < plane.rows; ++y) {
    const int16_t* f = fixed.ptr<int16_t>(y);
    float* c = confidence->ptr<float>(y);
    for (int x = 0; x < plane.cols; ++x) {
      if (f[x] == kMarker) c[x] = std::min(c[x], confidence_cap);
    }
  }
}

void FillLowConfidence(const cv::Mat& guide_bgr,
                       const cv::Mat& confidence,
                       float fill_confidence,
                       float min_value,
                       float max_value,
                       cv::Mat* inverse_depth) {
  if (fill_confidence <= 0) return;
  // Smoothing strength and colour edge threshold of the fast global smoother (Min et al. 2014),
  // in the range OpenCV's WLS disparity filter uses; 8-bit colour units.
  constexpr double kLambda = 4000.0;
  constexpr double kSigmaColor = 4.0;
  cv::Mat weighted[2];
  cv::multiply(*inverse_depth, confidence, weighted[0]);
  weighted[1] = confidence;
  cv::Mat stacked, smoothed;
  cv::merge(weighted, 2, stacked);
  cv::ximgproc::fastGlobalSmootherFilter(guide_bgr, stacked, smoothed, kLambda, kSigmaColor);
  for (int y = 0; y < inverse_depth->rows; ++y) {
    const float* s = smoothed.ptr<float>(y);
    const float* c = confidence.ptr<float>(y);
    float* v = inverse_depth->ptr<float>(y);
    for (int x = 0; x < inverse_depth->cols; ++x) {
      if (c[x] >= fill_confidence || s[2 * x + 1] <= 1e-6f) continue;
      const float filled = std::clamp(s[2 * x] / s[2 * x + 1], min_value, max_value);
      const float keep = c[x] / fill_confidence;
      v[x] = keep * v[x] + (1 - keep) * filled;
    }
  }
}

void UpsampleJointBilateral(const cv::Mat& low_value,
                            const cv::Mat& low_confidence,
                            const cv::Mat& low_guide_bgr,
                            const cv::Mat& high_guide_bgr,
                            cv::Mat* high_value,
                            cv::Mat* high_confidence) {
  PX_CHECK(low_value.size() == low_confidence.size() && low_value.size() == low_guide_bgr.size());
  PX_CHECK(low_guide_bgr.type() == CV_8UC3 && high_guide_bgr.type() == CV_8UC3);
  // Spatial sigma in low-resolution pixels (about one sample) and colour sigma in 8-bit units.
  constexpr float kSigmaSpatial = 0.7f;
  constexpr float kSigmaColor = 12.0f;
  // A floor on the confidence weight, so a pixel whose neighbours are all unreliable still averages.
  constexpr float kConfidenceFloor = 0.02f;
  const float scale_x = static_cast<float>(low_value.cols) / high_guide_bgr.cols;
  const float scale_y = static_cast<float>(low_value.rows) / high_guide_bgr.rows;
  std::vector<float> colour_weight(3 * 255 * 255 + 1);
  for (size_t d2 = 0; d2 < colour_weight.size(); ++d2) {
    colour_weight[d2] = std::exp(-static_cast<float>(d2) / (2 * kSigmaColor * kSigmaColor));
  }
  // Separable spatial weights: per output column the nearest low-resolution column and the
  // weights of its three neighbours; the same per output row.
  const auto spatial =
      [&](int count, float scale, int low_count, std::vector<int>* centre, std::vector<float>* weights) {
        centre->resize(count);
        weights->resize(3 * count);
        for (int i = 0; i < count; ++i) {
          const float l = (i + 0.5f) * scale - 0.5f;
          (*centre)[i] = std::clamp(static_cast<int>(std::lround(l)), 0, low_count - 1);
          for (int k = 0; k < 3; ++k) {
            const float d = static_cast<float>((*centre)[i] + k - 1) - l;
            (*weights)[3 * i + k] = std::exp(-d * d / (2 * kSigmaSpatial * kSigmaSpatial));
          }
        }
      };
  std::vector<int> centre_x, centre_y;
  std::vector<float> weight_x, weight_y;
  spatial(high_guide_bgr.cols, scale_x, low_value.cols, &centre_x, &weight_x);
  spatial(high_guide_bgr.rows, scale_y, low_value.rows, &centre_y, &weight_y);

  high_value->create(high_guide_bgr.size(), CV_32F);
  high_confidence->create(high_guide_bgr.size(), CV_32F);
  cv::parallel_for_(cv::Range(0, high_guide_bgr.rows), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      const int cy = centre_y[y];
      const cv::Vec3b* guide = high_guide_bgr.ptr<cv::Vec3b>(y);
      float* value_out = high_value->ptr<float>(y);
      float* confidence_out = high_confidence->ptr<float>(y);
      for (int x = 0; x < high_guide_bgr.cols; ++x) {
        const int cx = centre_x[x];
        float sum_w = 0, sum_wv = 0, sum_u = 0, sum_uc = 0;
        for (int j = 0; j < 3; ++j) {
          const int qy = cy + j - 1;
          if (qy < 0 || qy >= low_value.rows) continue;
          const cv::Vec3b* low_guide = low_guide_bgr.ptr<cv::Vec3b>(qy);
          const float* v = low_value.ptr<float>(qy);
          const float* c = low_confidence.ptr<float>(qy);
          for (int i = 0; i < 3; ++i) {
            const int qx = cx + i - 1;
            if (qx < 0 || qx >= low_value.cols) continue;
            int colour_d2 = 0;
            for (int k = 0; k < 3; ++k) {
              const int d = guide[x][k] - low_guide[qx][k];
              colour_d2 += d * d;
            }
            const float u = weight_y[3 * y + j] * weight_x[3 * x + i] * colour_weight[colour_d2];
            const float w = u * std::max(c[qx], kConfidenceFloor);
            sum_u += u;
            sum_uc += u * c[qx];
            sum_w += w;
            sum_wv += w * v[qx];
          }
        }
        if (sum_w > 0 && sum_u > 0) {
          value_out[x] = sum_wv / sum_w;
          confidence_out[x] = sum_uc / sum_u;
        } else {  // every neighbour's colour is far off: take the nearest sample as it is
          value_out[x] = low_value.at<float>(cy, cx);
          confidence_out[x] = low_confidence.at<float>(cy, cx);
        }
      }
    }
  });
}

}  // namespace px::depth
