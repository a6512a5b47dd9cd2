// BGR24 frames into yuv420p planes with libswscale, for the encoders that take YUV (x264, WebP).
#pragma once

#include <opencv2/core.hpp>

extern "C" {
#include <libavutil/frame.h>
#include <libswscale/swscale.h>
}

#include "pipeline/core/status.h"

namespace px::clip {

class BgrToYuv420 {
 public:
  enum class Matrix { kBt709, kBt601 };  // H.264 HD tags BT.709; WebP is defined in BT.601
  ~BgrToYuv420();
  // Full-range BGR in, limited-range YUV out, width x height (the frame's own size).
  Status Init(int width, int height, Matrix matrix);
  // Converts the top-left width x height of `bgr` into `frame` (yuv420p, that size).
  void Convert(const cv::Mat& bgr, AVFrame* frame);

 private:
  int width_ = 0;
  int height_ = 0;
  SwsContext* sws_ = nullptr;
  cv::Mat staging_buffer_;  // owns the aligned rows staging_ views
  cv::Mat staging_;
};

}  // namespace px::clip
