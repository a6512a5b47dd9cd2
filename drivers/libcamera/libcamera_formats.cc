#include "drivers/libcamera/libcamera_formats.h"

#include <cstdio>

#include "pipeline/core/check.h"

namespace px::libcamera_driver {

const std::vector<FormatMapping>& SupportedFormats() {
  static const std::vector<FormatMapping> kFormats = {
      {kFourccRgb888, "RGB888", PixelFormat::kBgr888},
      {kFourccBgr888, "BGR888", PixelFormat::kRgb888},
      {kFourccYuyv, "YUYV", PixelFormat::kYuyv},
      {kFourccNv12, "NV12", PixelFormat::kNv12},
      {kFourccSrggb8, "SRGGB8", PixelFormat::kBayerRggb8},
      {kFourccR8, "R8", PixelFormat::kGray8},
  };
  return kFormats;
}

std::optional<PixelFormat> PxFormatFromFourcc(uint32_t fourcc) {
  for (const FormatMapping& mapping : SupportedFormats()) {
    if (mapping.fourcc == fourcc) return mapping.px;
  }
  return std::nullopt;
}

uint32_t FourccFromPxFormat(PixelFormat format) {
  for (const FormatMapping& mapping : SupportedFormats()) {
    if (mapping.px == format) return mapping.fourcc;
  }
  PX_CHECK(false) << "no libcamera format for " << PixelFormatName(format);
  return 0;
}

std::string DescribeFourcc(uint32_t fourcc) {
  std::string code;
  bool printable = true;
  for (int i = 0; i < 4; ++i) {
    const char c = static_cast<char>((fourcc >> (8 * i)) & 0xff);
    printable = printable && c >= 0x20 && c < 0x7f;
    code += c;
  }
  if (!printable) {
    char hex[16];
    std::snprintf(hex, sizeof(hex), "0x%08x", fourcc);
    code = hex;
  }
  for (const FormatMapping& mapping : SupportedFormats()) {
    if (mapping.fourcc == fourcc) return std::string(mapping.libcamera_name) + " (" + code + ")";
  }
  return code;
}

}  // namespace px::libcamera_driver
