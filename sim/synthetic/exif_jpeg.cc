#include "sim/synthetic/exif_jpeg.h"

#include <cmath>

namespace px::sim {
namespace {

// Little-endian TIFF writer.
void U16(std::vector<uint8_t>* out, uint32_t value) {
  out->push_back(value & 0xFF);
  out->push_back(value >> 8 & 0xFF);
}
void U32(std::vector<uint8_t>* out, uint32_t value) {
  U16(out, value & 0xFFFF);
  U16(out, value >> 16);
}
void Entry(std::vector<uint8_t>* out, uint16_t tag, uint16_t type, uint32_t value) {
  U16(out, tag);
  U16(out, type);
  U32(out, 1);
  U32(out, value);  // a SHORT sits in the low bytes; a RATIONAL's field is its offset
}

constexpr uint16_t kShort = 3, kLong = 4, kRational = 5;

}  // namespace

std::vector<uint8_t> WithExifFocalLength(const std::vector<uint8_t>& jpeg, double focal_px, int width, int height) {
  // Layout: header (8), IFD0 with the Exif pointer (18), Exif IFD of 5 entries (66), 2 rationals.
  constexpr uint32_t kExifIfd = 26, kFocalAt = 92, kResolutionAt = 100;
  std::vector<uint8_t> tiff = {'I', 'I', 0x2A, 0};
  U32(&tiff, 8);
  U16(&tiff, 1);
  Entry(&tiff, 0x8769, kLong, kExifIfd);
  U32(&tiff, 0);
  U16(&tiff, 5);                                   // tags in ascending order
  Entry(&tiff, 0x920A, kRational, kFocalAt);       // FocalLength, mm
  Entry(&tiff, 0xA002, kLong, width);              // PixelXDimension
  Entry(&tiff, 0xA003, kLong, height);             // PixelYDimension
  Entry(&tiff, 0xA20E, kRational, kResolutionAt);  // FocalPlaneXResolution
  Entry(&tiff, 0xA210, kShort, 3);                 // FocalPlaneResolutionUnit: cm
  U32(&tiff, 0);
  U32(&tiff, static_cast<uint32_t>(std::lround(focal_px * 1000)));  // focal_px / 100 mm
  U32(&tiff, 100000);
  U32(&tiff, 1000);  // 1000 px per cm = 100 px per mm
  U32(&tiff, 1);

  const size_t length = 2 + 6 + tiff.size();
  std::vector<uint8_t> out(jpeg.begin(), jpeg.begin() + 2);  // SOI
  out.insert(out.end(), {0xFF, 0xE1, static_cast<uint8_t>(length >> 8), static_cast<uint8_t>(length & 0xFF)});
  out.insert(out.end(), {'E', 'x', 'i', 'f', 0, 0});
  out.insert(out.end(), tiff.begin(), tiff.end());
  out.insert(out.end(), jpeg.begin() + 2, jpeg.end());
  return out;
}

}  // namespace px::sim
