// Test-only: frames for the clip-format tests.
#pragma once

#include <cmath>
#include <cstdint>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace px::clip::testing {

// Smooth gradients and a disc drifting `step_px` a frame: compressible, every frame differs from
// its neighbours (~20 dB apart), and a frame mix-up or a broken palette shows in PSNR.
inline cv::Mat PatternFrame(int width, int height, int index, const cv::Scalar& disc_bgr, int step_px) {
  cv::Mat frame(height, width, CV_8UC3);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      frame.at<cv::Vec3b>(y, x) = cv::Vec3b(static_cast<uint8_t>(40 + 150 * x / width),
                                            static_cast<uint8_t>(60 + 120 * y / height),
                                            static_cast<uint8_t>(128 + 90 * std::sin(0.05 * (x + y) + 0.3 * index)));
    }
  }
  cv::circle(frame, cv::Point(10 + step_px * index, height / 2), height / 5, disc_bgr, cv::FILLED, cv::LINE_AA);
  return frame;
}

}  // namespace px::clip::testing
