// Turning one dequeued V4L2 buffer into a tightly packed px::RawImage in the pipeline's format:
// row strides (bytesperline) removed, RGB3 <-> BGR3 swapped when the pipeline wants the other
// order, MJPG decoded with OpenCV to BGR888 (or RGB888).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "pipeline/core/pixel_format.h"

namespace px::v4l2 {

// What S_FMT granted: the layout of every buffer.
struct BufferLayout {
  uint32_t fourcc = 0;
  int width = 0;
  int height = 0;
  uint32_t bytes_per_line = 0;  // of the first (or only) plane; NV12's UV rows use the same stride
  uint32_t size_image = 0;
};

// Bytes a complete uncompressed frame occupies in the buffer (the last row need not be padded);
// 0 for compressed formats, whose size varies.
size_t MinimumFrameBytes(const BufferLayout& layout);

// The result of converting one buffer: an image, or the reason the buffer is unusable (which
// the caller records as FrameStatus::kCorrupt, never as an error of the whole capture).
struct Converted {
  RawImage image;
  std::string problem;  // empty when image is good
};

// `data` holds `bytes_used` bytes of a buffer with `layout`. `output` is the pipeline format the
// caller negotiated for this fourcc (the fourcc's own format, its RGB/BGR twin, or for MJPG
// either of RGB888/BGR888). A short buffer or an undecodable JPEG gives a problem, not a crash.
Converted ConvertBuffer(const uint8_t* data, size_t bytes_used, const BufferLayout& layout, PixelFormat output);

}  // namespace px::v4l2
