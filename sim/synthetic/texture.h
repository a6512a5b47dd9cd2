// An image texture with a mip pyramid, sampled trilinearly: bilinear within a level, linear
// between the two levels that bracket the sample footprint, so distant textures do not alias.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace px::sim {

class MipTexture {
 public:
  // `bgr` is CV_8UC3; levels halve (area-averaged) down to 1 pixel on the shorter side.
  explicit MipTexture(const cv::Mat& bgr);

  int width() const { return levels_[0].cols; }
  int height() const { return levels_[0].rows; }
  int num_levels() const { return static_cast<int>(levels_.size()); }
  const cv::Mat& level(int i) const { return levels_[i]; }  // CV_32FC3, 8-bit levels

  // (u, v) in [0, 1] across the texture (0,0 = top-left corner of the top-left texel);
  // outside that range it is clamped to the edge, or wrapped when `wrap`. `level` is the
  // fractional mip level (0 = full resolution); it is clamped to the pyramid.
  cv::Vec3f Sample(double u, double v, double level, bool wrap) const;

 private:
  cv::Vec3f SampleLevel(int level, double u, double v, bool wrap) const;

  std::vector<cv::Mat> levels_;
};

}  // namespace px::sim
