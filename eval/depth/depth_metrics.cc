#include "eval/depth/depth_metrics.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "pipeline/core/check.h"
#include "pipeline/core/order_statistics.h"

namespace px::eval {
namespace {

double Percent(int64_t part, int64_t whole) { return whole > 0 ? 100.0 * part / whole : 0.0; }

}  // namespace

HciMetrics EvaluateHciDisparity(const cv::Mat& disparity, const cv::Mat& gt_disparity, int boundary_px) {
  PX_CHECK(disparity.type() == CV_32F && gt_disparity.type() == CV_32F && disparity.size() == gt_disparity.size());
  HciMetrics metrics;
  int64_t bad_007 = 0, bad_003 = 0, finite = 0;
  double squared = 0;
  for (int y = boundary_px; y < disparity.rows - boundary_px; ++y) {
    for (int x = boundary_px; x < disparity.cols - boundary_px; ++x) {
      const float gt = gt_disparity.at<float>(y, x);
      if (!std::isfinite(gt)) continue;
      ++metrics.pixels;
      const float d = disparity.at<float>(y, x);
      if (!std::isfinite(d)) {
        ++bad_007;
        ++bad_003;
        continue;
      }
      const double error = std::abs(d - gt);
      bad_007 += error > 0.07 ? 1 : 0;
      bad_003 += error > 0.03 ? 1 : 0;
      squared += error * error;
      ++finite;
    }
  }
  metrics.bad_pix_007 = Percent(bad_007, metrics.pixels);
  metrics.bad_pix_003 = Percent(bad_003, metrics.pixels);
  metrics.mse_x100 = finite > 0 ? 100.0 * squared / finite : 0.0;
  return metrics;
}

StereoMetrics EvaluateStereoDisparity(const cv::Mat& disparity, const cv::Mat& gt_disparity) {
  PX_CHECK(disparity.type() == CV_32F && gt_disparity.type() == CV_32F && disparity.size() == gt_disparity.size());
  StereoMetrics metrics;
  int64_t bad_1 = 0, bad_2 = 0;
  double sum = 0;
  for (int y = 0; y < disparity.rows; ++y) {
    for (int x = 0; x < disparity.cols; ++x) {
      const float gt = gt_disparity.at<float>(y, x);
      if (!std::isfinite(gt)) continue;
      ++metrics.pixels;
      const float d = disparity.at<float>(y, x);
      const double error = std::isfinite(d) ? std::abs(d - gt) : std::abs(gt);
      bad_1 += error > 1.0 ? 1 : 0;
      bad_2 += error > 2.0 ? 1 : 0;
      sum += error;
    }
  }
  metrics.bad_1 = Percent(bad_1, metrics.pixels);
  metrics.bad_2 = Percent(bad_2, metrics.pixels);
  metrics.avg_error = metrics.pixels > 0 ? sum / metrics.pixels : 0.0;
  return metrics;
}

cv::Mat DepthEdgeMask(const cv::Mat& gt_depth_m, int radius_px) {
  PX_CHECK(gt_depth_m.type() == CV_32F);
  cv::Mat edges = cv::Mat::zeros(gt_depth_m.size(), CV_8U);
  const auto jump = [](float a, float b) {
    if (a <= 0 || b <= 0) return (a <= 0) != (b <= 0);
    return std::abs(a - b) > 0.05f * std::min(a, b);
  };
  for (int y = 0; y < gt_depth_m.rows; ++y) {
    for (int x = 0; x < gt_depth_m.cols; ++x) {
      const float z = gt_depth_m.at<float>(y, x);
      if ((x + 1 < gt_depth_m.cols && jump(z, gt_depth_m.at<float>(y, x + 1))) ||
          (y + 1 < gt_depth_m.rows && jump(z, gt_depth_m.at<float>(y + 1, x)))) {
        edges.at<uchar>(y, x) = 255;
      }
    }
  }
  if (radius_px > 0) {
    cv::dilate(
        edges, edges, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * radius_px + 1, 2 * radius_px + 1)));
  }
  return edges;
}

DepthErrorMetrics EvaluateDepth(const cv::Mat& depth_m, const cv::Mat& gt_depth_m, int edge_radius_px) {
  PX_CHECK(depth_m.type() == CV_32F && gt_depth_m.type() == CV_32F && depth_m.size() == gt_depth_m.size());
  const cv::Mat edges = DepthEdgeMask(gt_depth_m, edge_radius_px);
  std::vector<float> all, near_edges;
  int64_t bad = 0, edge_bad = 0;
  for (int y = 0; y < depth_m.rows; ++y) {
    for (int x = 0; x < depth_m.cols; ++x) {
      const float gt = gt_depth_m.at<float>(y, x);
      if (!(gt > 0)) continue;
      const float z = depth_m.at<float>(y, x);
      const float error = std::isfinite(z) && z > 0 ? std::abs(z - gt) / gt : 1.0f;
      all.push_back(error);
      bad += error > 0.05f ? 1 : 0;
      if (edges.at<uchar>(y, x) != 0) {
        near_edges.push_back(error);
        edge_bad += error > 0.05f ? 1 : 0;
      }
    }
  }
  DepthErrorMetrics metrics;
  metrics.pixels = static_cast<int64_t>(all.size());
  metrics.edge_pixels = static_cast<int64_t>(near_edges.size());
  metrics.bad_5_percent = Percent(bad, metrics.pixels);
  metrics.edge_bad_5_percent = Percent(edge_bad, metrics.edge_pixels);
  metrics.median_relative = Median(std::move(all));
  metrics.edge_median_relative = Median(std::move(near_edges));
  return metrics;
}

}  // namespace px::eval
