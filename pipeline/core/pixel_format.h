// Sensor pixel formats and the raw image buffer a sensor (real or simulated) delivers.
// Processed images in the pipeline are cv::Mat CV_8UC3 in OpenCV's BGR order.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "pipeline/core/status.h"

namespace px {

enum class PixelFormat {
  kRgb888,      // 3 bytes per pixel, R G B
  kBgr888,      // 3 bytes per pixel, B G R (OpenCV's order)
  kGray8,       // 1 byte per pixel
  kYuyv,        // 4:2:2 packed Y0 U Y1 V, BT.601 limited range; width must be even
  kNv12,        // 4:2:0 planar Y then interleaved UV, BT.601 limited range; even width and height
  kBayerRggb8,  // raw Bayer mosaic, 8 bits, R at (0,0); even width and height
};

// Canonical names as used in recordings: "RGB888", "BGR888", "GRAY8", "YUYV", "NV12", "SRGGB8".
std::string_view PixelFormatName(PixelFormat format);
std::optional<PixelFormat> ParsePixelFormat(std::string_view name);

// Bytes needed for a tightly packed image of this format, or an error naming the reason
// (odd width for YUYV, odd size for NV12 and Bayer, non-positive size).
StatusOr<size_t> PackedImageBytes(PixelFormat format, int width, int height);

// One image as it comes off a sensor: tightly packed bytes in `format`.
struct RawImage {
  PixelFormat format = PixelFormat::kBgr888;
  int width = 0;
  int height = 0;
  std::vector<uint8_t> bytes;

  // OK when the buffer holds exactly PackedImageBytes(format, width, height) bytes.
  Status Validate() const;
};

// Decodes any supported format to BGR (Bayer by OpenCV's edge-aware demosaic). Fails with
// DATA_LOSS on a short buffer, INVALID_ARGUMENT on impossible sizes.
StatusOr<cv::Mat> ToBgr(const RawImage& raw);

// Encodes a CV_8UC3 BGR image into `format` (what a sensor of that format would deliver).
StatusOr<RawImage> FromBgr(const cv::Mat& bgr, PixelFormat format);

}  // namespace px
