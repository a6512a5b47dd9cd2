// The pixel formats the libcamera driver can turn into px::RawImage, keyed by the DRM fourcc
// that libcamera::PixelFormat carries. No libcamera header here, so the table is unit-testable;
// libcamera_source.cc static_asserts that the codes equal libcamera::formats::*.
//
// Mind the names: libcamera (like DRM) names packed RGB by the 24-bit word read little-endian,
// so libcamera "RGB888" is B,G,R in memory (px kBgr888) and "BGR888" is R,G,B (px kRgb888).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "pipeline/core/pixel_format.h"

namespace px::libcamera_driver {

constexpr uint32_t Fourcc(char a, char b, char c, char d) {
  return static_cast<uint32_t>(static_cast<uint8_t>(a)) | (static_cast<uint32_t>(static_cast<uint8_t>(b)) << 8) |
         (static_cast<uint32_t>(static_cast<uint8_t>(c)) << 16) |
         (static_cast<uint32_t>(static_cast<uint8_t>(d)) << 24);
}

constexpr uint32_t kFourccRgb888 = Fourcc('R', 'G', '2', '4');  // libcamera RGB888: bytes B, G, R
constexpr uint32_t kFourccBgr888 = Fourcc('B', 'G', '2', '4');  // libcamera BGR888: bytes R, G, B
constexpr uint32_t kFourccYuyv = Fourcc('Y', 'U', 'Y', 'V');
constexpr uint32_t kFourccNv12 = Fourcc('N', 'V', '1', '2');
constexpr uint32_t kFourccSrggb8 = Fourcc('R', 'G', 'G', 'B');
constexpr uint32_t kFourccR8 = Fourcc('R', '8', ' ', ' ');

struct FormatMapping {
  uint32_t fourcc;
  std::string_view libcamera_name;  // as libcamera::PixelFormat::toString() prints it
  PixelFormat px;
};

// Every supported pair, in the order the driver falls back to them when the camera refuses the
// wanted format (cheapest conversion to the pipeline's BGR first).
const std::vector<FormatMapping>& SupportedFormats();

// The px format of a libcamera fourcc; nullopt for formats we cannot convert (MJPEG, 10-bit Bayer...).
std::optional<PixelFormat> PxFormatFromFourcc(uint32_t fourcc);
// The libcamera fourcc delivering exactly the bytes of `format` (every px format has one).
uint32_t FourccFromPxFormat(PixelFormat format);
// "RGB888 (RG24)" for a known code, else the four characters ("MJPG") or hex for unprintable ones.
std::string DescribeFourcc(uint32_t fourcc);

}  // namespace px::libcamera_driver
