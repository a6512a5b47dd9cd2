#include "pipeline/run/palette_dither.h"

#include <array>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace px {

int CountColoursUpTo(const RawImage& image, int limit) {
  if (image.format != PixelFormat::kRgb888 && image.format != PixelFormat::kBgr888) return limit + 1;
  // One bit per 24-bit colour (2 MiB): a photo passes the limit within its first rows.
  std::vector<uint64_t> seen((1u << 24) / 64, 0);
  int count = 0;
  const size_t pixels = image.bytes.size() / 3;
  for (size_t i = 0; i < pixels; ++i) {
    const uint8_t* p = image.bytes.data() + 3 * i;
    const uint32_t colour = (uint32_t{p[0]} << 16) | (uint32_t{p[1]} << 8) | p[2];
    uint64_t& word = seen[colour >> 6];
    const uint64_t bit = uint64_t{1} << (colour & 63);
    if ((word & bit) != 0) continue;
    word |= bit;
    if (++count > limit) return count;
  }
  return count;
}

cv::Mat RemoveDither(const cv::Mat& bgr) {
  const cv::Mat kernel = (cv::Mat_<float>(1, 5) << 1.f / 16, 4.f / 16, 6.f / 16, 4.f / 16, 1.f / 16);
  cv::Mat smooth;
  cv::sepFilter2D(bgr, smooth, -1, kernel, kernel, cv::Point(-1, -1), 0, cv::BORDER_REFLECT_101);
  return smooth;
}

double PixelScaleResidual(const cv::Mat& bgr, cv::Mat* without_dither) {
  if (bgr.empty() || bgr.type() != CV_8UC3) return 0.0;
  const cv::Mat smooth = RemoveDither(bgr);
  if (without_dither != nullptr) *without_dither = smooth;
  cv::Mat difference;
  cv::absdiff(bgr, smooth, difference);
  // Per pixel the channels' sum, 0..765; its median by histogram.
  std::array<int64_t, 766> histogram{};
  for (int y = 0; y < difference.rows; ++y) {
    const cv::Vec3b* row = difference.ptr<cv::Vec3b>(y);
    for (int x = 0; x < difference.cols; ++x) ++histogram[row[x][0] + row[x][1] + row[x][2]];
  }
  const int64_t half = static_cast<int64_t>(difference.total()) / 2;
  int64_t seen = 0;
  for (size_t sum = 0; sum < histogram.size(); ++sum) {
    seen += histogram[sum];
    if (seen > half) return static_cast<double>(sum) / 3.0;
  }
  return 0.0;
}

}  // namespace px
