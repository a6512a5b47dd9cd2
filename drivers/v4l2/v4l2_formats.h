// V4L2 pixel formats (fourccs) as the pipeline sees them, and what a device offers
// (VIDIOC_ENUM_FMT, VIDIOC_ENUM_FRAMESIZES).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pipeline/core/pixel_format.h"

namespace px::v4l2 {

// "YUYV", "MJPG", "RGB3"; unprintable bytes as '?'.
std::string FourccName(uint32_t fourcc);

// The fourcc that carries `format` unchanged: RGB888 -> RGB3, BGR888 -> BGR3, GRAY8 -> GREY,
// YUYV -> YUYV, NV12 -> NV12, SRGGB8 -> RGGB.
uint32_t FourccFor(PixelFormat format);
// The inverse; nullopt for fourccs the pipeline has no format for (MJPG among them).
std::optional<PixelFormat> PixelFormatForFourcc(uint32_t fourcc);
// Every fourcc this driver can read: the six above plus MJPG (decoded to BGR888).
bool DriverReadsFourcc(uint32_t fourcc);
std::string DriverFourccList();  // "RGB3, BGR3, GREY, YUYV, NV12, RGGB, MJPG"

struct FrameSize {
  int width = 0;
  int height = 0;
  friend bool operator==(const FrameSize&, const FrameSize&) = default;
};

// One VIDIOC_ENUM_FMT entry with its VIDIOC_ENUM_FRAMESIZES answer.
struct DeviceFormat {
  uint32_t fourcc = 0;
  std::string description;                      // the driver's text, e.g. "YUYV 4:2:2"
  bool compressed = false;                      // V4L2_FMT_FLAG_COMPRESSED
  std::vector<FrameSize> sizes;                 // discrete sizes, largest first; empty when stepwise or not enumerable
  std::optional<FrameSize> min_size, max_size;  // stepwise or continuous ranges
  int step_width = 0, step_height = 0;

  // "YUYV 504x384" / "YUYV 16x16..1920x1080/8x8" / "YUYV (sizes not listed)"
  std::string ToString() const;
};

// Lists the single-planar capture formats of an open device. A device without ENUM_FRAMESIZES
// (ENOTTY, EINVAL on index 0) gets no sizes, not an error.
StatusOr<std::vector<DeviceFormat>> EnumerateFormats(int fd, const std::string& device);

// "BGR3 504x384; MJPG 504x384" for error messages.
std::string DescribeFormats(const std::vector<DeviceFormat>& formats);

}  // namespace px::v4l2
