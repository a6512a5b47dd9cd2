#include "drivers/libcamera/plane_copy.h"

#include <cstring>
#include <string>

namespace px::libcamera_driver {

StatusOr<std::vector<PackedPlane>> PackedPlanes(PixelFormat format, int width, int height) {
  PX_ASSIGN_OR_RETURN(size_t total, PackedImageBytes(format, width, height));
  (void)total;  // only for its size checks (odd sizes for YUYV, NV12, Bayer)
  const size_t w = static_cast<size_t>(width);
  switch (format) {
    case PixelFormat::kRgb888:
    case PixelFormat::kBgr888:
      return std::vector<PackedPlane>{{3 * w, height}};
    case PixelFormat::kYuyv:
      return std::vector<PackedPlane>{{2 * w, height}};
    case PixelFormat::kGray8:
    case PixelFormat::kBayerRggb8:
      return std::vector<PackedPlane>{{w, height}};
    case PixelFormat::kNv12:
      return std::vector<PackedPlane>{{w, height}, {w, height / 2}};
  }
  return InvalidArgumentError("unknown pixel format");
}

StatusOr<RawImage> CopyPlanes(PixelFormat format, int width, int height, const std::vector<PlaneView>& planes) {
  PX_ASSIGN_OR_RETURN(std::vector<PackedPlane> layout, PackedPlanes(format, width, height));
  const std::string what =
      std::string(PixelFormatName(format)) + " " + std::to_string(width) + "x" + std::to_string(height);
  std::vector<PlaneView> sources = planes;
  if (layout.size() == 2 && sources.size() == 1) {
    // One buffer holding both planes: UV follows Y's rows at the same stride.
    const PlaneView& y = sources[0];
    const size_t stride = y.stride != 0 ? y.stride : layout[0].row_bytes;
    const size_t y_span = stride * static_cast<size_t>(layout[0].rows);
    PlaneView uv;
    uv.data = y.data + y_span;
    uv.bytes = y.bytes > y_span ? y.bytes - y_span : 0;
    uv.stride = stride;
    sources.push_back(uv);
  }
  if (sources.size() != layout.size()) {
    return InvalidArgumentError(what + ": got " + std::to_string(planes.size()) + " plane(s), want " +
                                std::to_string(layout.size()));
  }
  RawImage image;
  image.format = format;
  image.width = width;
  image.height = height;
  size_t total = 0;
  for (const PackedPlane& p : layout) total += p.row_bytes * static_cast<size_t>(p.rows);
  image.bytes.resize(total);
  uint8_t* out = image.bytes.data();
  for (size_t i = 0; i < layout.size(); ++i) {
    const PackedPlane& p = layout[i];
    const PlaneView& src = sources[i];
    const size_t stride = src.stride != 0 ? src.stride : p.row_bytes;
    if (stride < p.row_bytes) {
      return InvalidArgumentError(what + ": plane " + std::to_string(i) + " stride " + std::to_string(stride) +
                                  " is below its row size " + std::to_string(p.row_bytes));
    }
    // The last row need not carry padding.
    const size_t need = stride * static_cast<size_t>(p.rows - 1) + p.row_bytes;
    if (src.data == nullptr || src.bytes < need) {
      return DataLossError(what + ": plane " + std::to_string(i) + " has " + std::to_string(src.bytes) + " bytes, " +
                           std::to_string(p.rows) + " rows of " + std::to_string(p.row_bytes) + " bytes at stride " +
                           std::to_string(stride) + " need " + std::to_string(need));
    }
    if (stride == p.row_bytes) {
      std::memcpy(out, src.data, need);
      out += need;
    } else {
      for (int row = 0; row < p.rows; ++row) {
        std::memcpy(out, src.data + stride * static_cast<size_t>(row), p.row_bytes);
        out += p.row_bytes;
      }
    }
  }
  return image;
}

}  // namespace px::libcamera_driver
