// A frame sink for tests that need only how many frames a run handed on and their size.
#pragma once

#include <opencv2/core.hpp>

#include "pipeline/run/pipeline.h"

namespace px::testing {

class CountingFrameSink : public FrameSink {
 public:
  Status Consume(int, const cv::Mat& bgr) override {
    ++frames;
    size = bgr.size();
    return OkStatus();
  }
  int frames = 0;
  cv::Size size;  // the last frame's
};

}  // namespace px::testing
