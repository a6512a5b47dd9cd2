#include "sim/synthetic/texture.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "pipeline/core/check.h"

namespace px::sim {

MipTexture::MipTexture(const cv::Mat& bgr) {
  PX_CHECK(bgr.type() == CV_8UC3 && !bgr.empty()) << "texture must be non-empty CV_8UC3";
  cv::Mat level;
  bgr.convertTo(level, CV_32FC3);
  levels_.push_back(level);
  while (std::min(level.cols, level.rows) > 1) {
    cv::Mat smaller;
    cv::resize(
        level, smaller, cv::Size(std::max(1, level.cols / 2), std::max(1, level.rows / 2)), 0, 0, cv::INTER_AREA);
    levels_.push_back(smaller);
    level = smaller;
  }
}

cv::Vec3f MipTexture::SampleLevel(int level, double u, double v, bool wrap) const {
  const cv::Mat& image = levels_[level];
  const int w = image.cols, h = image.rows;
  if (wrap) {
    u -= std::floor(u);
    v -= std::floor(v);
  }
  // Texel centres sit at (i + 0.5) / w.
  const double x = u * w - 0.5, y = v * h - 0.5;
  const double fx = std::floor(x), fy = std::floor(y);
  const float ax = static_cast<float>(x - fx), ay = static_cast<float>(y - fy);
  int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
  int x1 = x0 + 1, y1 = y0 + 1;
  if (wrap) {
    x0 = (x0 % w + w) % w;
    x1 = (x1 % w + w) % w;
    y0 = (y0 % h + h) % h;
    y1 = (y1 % h + h) % h;
  } else {
    x0 = std::clamp(x0, 0, w - 1);
    x1 = std::clamp(x1, 0, w - 1);
    y0 = std::clamp(y0, 0, h - 1);
    y1 = std::clamp(y1, 0, h - 1);
  }
  const cv::Vec3f* row0 = image.ptr<cv::Vec3f>(y0);
  const cv::Vec3f* row1 = image.ptr<cv::Vec3f>(y1);
  const cv::Vec3f top = row0[x0] + (row0[x1] - row0[x0]) * ax;
  const cv::Vec3f bottom = row1[x0] + (row1[x1] - row1[x0]) * ax;
  return top + (bottom - top) * ay;
}

cv::Vec3f MipTexture::Sample(double u, double v, double level, bool wrap) const {
  const double clamped = std::clamp(level, 0.0, static_cast<double>(num_levels() - 1));
  const int l0 = static_cast<int>(clamped);
  const float t = static_cast<float>(clamped - l0);
  const cv::Vec3f a = SampleLevel(l0, u, v, wrap);
  if (t <= 0.0f || l0 + 1 >= num_levels()) return a;
  const cv::Vec3f b = SampleLevel(l0 + 1, u, v, wrap);
  return a + (b - a) * t;
}

}  // namespace px::sim
