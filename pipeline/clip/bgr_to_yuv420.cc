#include "pipeline/clip/bgr_to_yuv420.h"

#include <cstdint>

namespace px::clip {

BgrToYuv420::~BgrToYuv420() { sws_freeContext(sws_); }

Status BgrToYuv420::Init(int width, int height, Matrix matrix) {
  width_ = width;
  height_ = height;
  sws_ = sws_getContext(
      width, height, AV_PIX_FMT_BGR24, width, height, AV_PIX_FMT_YUV420P, SWS_BILINEAR, nullptr, nullptr, nullptr);
  if (sws_ == nullptr)
    return InternalError("no BGR24 to yuv420p converter for " + std::to_string(width) + "x" + std::to_string(height));
  const int* coefficients = sws_getCoefficients(matrix == Matrix::kBt709 ? SWS_CS_ITU709 : SWS_CS_ITU601);
  sws_setColorspaceDetails(sws_, coefficients, 1, coefficients, 0, 0, 1 << 16, 1 << 16);
  return OkStatus();
}

void BgrToYuv420::Convert(const cv::Mat& bgr, AVFrame* frame) {
  cv::Mat source = bgr(cv::Rect(0, 0, width_, height_));
  // libswscale's SIMD paths want rows on 16-byte boundaries (32 with AVX2); copy rows that are not.
  constexpr size_t kAlignment = 64;
  if (source.step[0] % kAlignment != 0 || reinterpret_cast<uintptr_t>(source.data) % kAlignment != 0) {
    if (staging_.empty()) {
      const size_t padded = (static_cast<size_t>(width_) * 3 + kAlignment - 1) / kAlignment * kAlignment;
      staging_buffer_ = cv::Mat(height_ + 1, static_cast<int>(padded), CV_8U);  // + a row: SIMD reads run past
      staging_ = cv::Mat(height_, width_, CV_8UC3, staging_buffer_.data, padded);
    }
    source.copyTo(staging_);
    source = staging_;
  }
  const uint8_t* planes[1] = {source.data};
  const int strides[1] = {static_cast<int>(source.step[0])};
  sws_scale(sws_, planes, strides, 0, height_, frame->data, frame->linesize);
}

}  // namespace px::clip
