// What can honestly be used of a lattice frame that did not arrive as configured: a frame in
// another pixel format decodes as what it says it is, and a truncated transfer still holds the
// rows at the top of the sensor whole (tiles lying entirely inside them are good views).
#pragma once

#include <cstddef>
#include <opencv2/core.hpp>

#include "pipeline/core/pixel_format.h"

namespace px {

// Rows at the top of a width x height `format` image that `bytes` bytes fill completely, with a
// margin for the rows a demosaic reads across (Bayer). NV12 keeps its chroma after all the luma,
// so a transfer that stops inside the luma plane leaves no whole row.
int CompleteRows(PixelFormat format, int width, int height, size_t bytes);

struct SalvagedFrame {
  cv::Mat bgr;            // the whole frame, zeros where nothing arrived
  int complete_rows = 0;  // rows [0, complete_rows) arrived whole
  size_t bytes_arrived = 0;
  size_t bytes_expected = 0;
};

// For a short buffer (more than nothing, less than its size needs): decodes what arrived.
// INVALID_ARGUMENT when the buffer is not short or the size is impossible.
StatusOr<SalvagedFrame> SalvageTruncatedFrame(const RawImage& image);

}  // namespace px
