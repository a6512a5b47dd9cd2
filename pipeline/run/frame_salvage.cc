#include "pipeline/run/frame_salvage.h"

#include <algorithm>
#include <string>

namespace px {

int CompleteRows(PixelFormat format, int width, int height, size_t bytes) {
  if (width <= 0 || height <= 0) return 0;
  const size_t w = static_cast<size_t>(width);
  size_t rows = 0;
  switch (format) {
    case PixelFormat::kRgb888:
    case PixelFormat::kBgr888:
      rows = bytes / (3 * w);
      break;
    case PixelFormat::kGray8:
      rows = bytes / w;
      break;
    case PixelFormat::kBayerRggb8:
      // The demosaic reads a row or two beyond each output row.
      rows = bytes / w >= 2 ? bytes / w - 2 : 0;
      break;
    case PixelFormat::kYuyv:
      rows = bytes / (2 * w);
      break;
    case PixelFormat::kNv12: {
      const size_t luma = w * static_cast<size_t>(height);
      rows = bytes <= luma ? 0 : 2 * ((bytes - luma) / w);
      break;
    }
  }
  return static_cast<int>(std::min(rows, static_cast<size_t>(height)));
}

StatusOr<SalvagedFrame> SalvageTruncatedFrame(const RawImage& image) {
  PX_ASSIGN_OR_RETURN(size_t expected, PackedImageBytes(image.format, image.width, image.height));
  if (image.bytes.empty() || image.bytes.size() >= expected) {
    return InvalidArgumentError("not a truncated buffer: " + std::to_string(image.bytes.size()) + " of " +
                                std::to_string(expected) + " bytes");
  }
  RawImage padded = image;
  padded.bytes.resize(expected, 0);
  SalvagedFrame salvaged;
  PX_ASSIGN_OR_RETURN(salvaged.bgr, ToBgr(padded));
  salvaged.complete_rows = CompleteRows(image.format, image.width, image.height, image.bytes.size());
  salvaged.bytes_arrived = image.bytes.size();
  salvaged.bytes_expected = expected;
  return salvaged;
}

}  // namespace px
