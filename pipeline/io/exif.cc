#include "pipeline/io/exif.h"

#include <cmath>
#include <fstream>
#include <iterator>

namespace px {

namespace {

// A TIFF block (the APP1 payload after "Exif\0\0"), in either byte order.
class TiffReader {
 public:
  TiffReader(const uint8_t* data, size_t size, size_t file_offset)
      : data_(data), size_(size), file_offset_(file_offset) {}

  Status Init() {
    if (size_ < 8) return Truncated(0);
    if (data_[0] == 'I' && data_[1] == 'I') {
      little_ = true;
    } else if (data_[0] == 'M' && data_[1] == 'M') {
      little_ = false;
    } else {
      return InvalidArgumentError("EXIF: no TIFF byte-order mark at byte " + std::to_string(file_offset_));
    }
    return OkStatus();
  }
  bool Has(size_t offset, size_t bytes) const { return offset <= size_ && bytes <= size_ - offset; }
  uint16_t U16(size_t at) const {
    return little_ ? static_cast<uint16_t>(data_[at] | data_[at + 1] << 8)
                   : static_cast<uint16_t>(data_[at] << 8 | data_[at + 1]);
  }
  uint32_t U32(size_t at) const {
    return little_ ? static_cast<uint32_t>(data_[at]) | static_cast<uint32_t>(data_[at + 1]) << 8 |
                         static_cast<uint32_t>(data_[at + 2]) << 16 | static_cast<uint32_t>(data_[at + 3]) << 24
                   : static_cast<uint32_t>(data_[at]) << 24 | static_cast<uint32_t>(data_[at + 1]) << 16 |
                         static_cast<uint32_t>(data_[at + 2]) << 8 | static_cast<uint32_t>(data_[at + 3]);
  }
  Status Truncated(size_t at) const {
    return DataLossError("EXIF: truncated at byte " + std::to_string(file_offset_ + at));
  }

  // Visits one IFD's entries: fn(tag, type, count, value_offset_field_position).
  template <typename Fn>
  Status VisitIfd(size_t offset, Fn fn) const {
    if (!Has(offset, 2)) return Truncated(offset);
    const int count = U16(offset);
    if (!Has(offset + 2, 12u * count)) return Truncated(offset + 2);
    for (int i = 0; i < count; ++i) {
      const size_t entry = offset + 2 + 12u * i;
      fn(U16(entry), U16(entry + 2), U32(entry + 4), entry + 8);
    }
    return OkStatus();
  }

  // Numeric value of an entry (SHORT, LONG or RATIONAL; the first of `count`); 0 if unreadable.
  double Number(uint16_t type, size_t field) const {
    if (type == 3) return U16(field);
    if (type == 4) return U32(field);
    if (type == 5 || type == 10) {
      const size_t at = U32(field);
      if (!Has(at, 8)) return 0;
      const double denominator =
          type == 5 ? static_cast<double>(U32(at + 4)) : static_cast<double>(static_cast<int32_t>(U32(at + 4)));
      const double numerator =
          type == 5 ? static_cast<double>(U32(at)) : static_cast<double>(static_cast<int32_t>(U32(at)));
      return denominator != 0 ? numerator / denominator : 0;
    }
    return 0;
  }

  std::string Ascii(uint32_t count, size_t field) const {
    const size_t at = count <= 4 ? field : U32(field);
    if (!Has(at, count)) return "";
    std::string text(reinterpret_cast<const char*>(data_ + at), count);
    while (!text.empty() && (text.back() == '\0' || text.back() == ' ')) text.pop_back();
    return text;
  }

 private:
  const uint8_t* data_;
  size_t size_;
  size_t file_offset_;
  bool little_ = true;
};

constexpr uint16_t kMake = 0x010F, kModel = 0x0110, kOrientation = 0x0112, kExifIfd = 0x8769;
constexpr uint16_t kFocalLength = 0x920A, kFocal35mm = 0xA405, kFocalPlaneX = 0xA20E, kFocalPlaneUnit = 0xA210;
constexpr uint16_t kPixelX = 0xA002, kPixelY = 0xA003;

Status ParseTiff(TiffReader tiff, ExifInfo* info) {
  PX_RETURN_IF_ERROR(tiff.Init());
  const size_t ifd0 = tiff.U32(4);
  size_t exif_ifd = 0;
  info->orientation = 0;
  PX_RETURN_IF_ERROR(tiff.VisitIfd(ifd0, [&](uint16_t tag, uint16_t type, uint32_t count, size_t field) {
    if (tag == kMake) info->make = tiff.Ascii(count, field);
    if (tag == kModel) info->model = tiff.Ascii(count, field);
    if (tag == kOrientation) info->orientation = static_cast<int>(tiff.Number(type, field));
    if (tag == kExifIfd) exif_ifd = tiff.U32(field);
  }));
  if (exif_ifd == 0) return OkStatus();
  int unit = 0;
  PX_RETURN_IF_ERROR(tiff.VisitIfd(exif_ifd, [&](uint16_t tag, uint16_t type, uint32_t, size_t field) {
    if (tag == kFocalLength) info->focal_length_mm = tiff.Number(type, field);
    if (tag == kFocal35mm) info->focal_length_35mm = tiff.Number(type, field);
    if (tag == kFocalPlaneX) info->focal_plane_x_resolution = tiff.Number(type, field);
    if (tag == kFocalPlaneUnit) unit = static_cast<int>(tiff.Number(type, field));
    if (tag == kPixelX) info->pixel_width = static_cast<int>(tiff.Number(type, field));
    if (tag == kPixelY) info->pixel_height = static_cast<int>(tiff.Number(type, field));
  }));
  // TIFF ResolutionUnit: 2 = inch (the default), 3 = centimetre.
  info->focal_plane_unit_mm = unit == 3 ? 10.0 : 25.4;
  return OkStatus();
}

}  // namespace

double ExifInfo::FocalPx(int width, int height, std::string* source) const {
  const int long_side = std::max(width, height);
  if (focal_length_mm > 0 && focal_plane_x_resolution > 0 && pixel_width > 0) {
    // The resolution is along the sensor's x, which is the Exif image's width (pre-rotation).
    const int exif_long = std::max(pixel_width, pixel_height);
    if (source != nullptr) *source = "EXIF focal length and focal plane resolution";
    return focal_length_mm * focal_plane_x_resolution / focal_plane_unit_mm * long_side / exif_long;
  }
  if (focal_length_35mm > 0) {
    if (source != nullptr) *source = "EXIF 35 mm equivalent focal length";
    return focal_length_35mm / 43.2666 * std::hypot(width, height);
  }
  return 0;
}

StatusOr<ExifInfo> ParseJpegExif(const std::vector<uint8_t>& bytes) {
  if (bytes.size() < 4 || bytes[0] != 0xFF || bytes[1] != 0xD8) {
    return InvalidArgumentError("not a JPEG (no start-of-image marker)");
  }
  ExifInfo info;
  size_t at = 2;
  while (at + 4 <= bytes.size()) {
    if (bytes[at] != 0xFF) return DataLossError("JPEG: no marker at byte " + std::to_string(at));
    const uint8_t marker = bytes[at + 1];
    if (marker == 0xDA || marker == 0xD9) break;  // image data: no EXIF after it
    const size_t length = static_cast<size_t>(bytes[at + 2]) << 8 | bytes[at + 3];
    if (length < 2 || at + 2 + length > bytes.size()) {
      return DataLossError("JPEG: segment at byte " + std::to_string(at) + " runs past the file");
    }
    const uint8_t* payload = bytes.data() + at + 4;
    const size_t payload_size = length - 2;
    if (marker == 0xE1 && payload_size > 6 && std::equal(payload, payload + 6, "Exif\0\0")) {
      TiffReader tiff(payload + 6, payload_size - 6, at + 10);
      PX_RETURN_IF_ERROR(ParseTiff(tiff, &info));
      return info;
    }
    at += 2 + length;
  }
  return info;
}

StatusOr<ExifInfo> ReadJpegExif(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return NotFoundError(file.string() + ": cannot open");
  const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  StatusOr<ExifInfo> info = ParseJpegExif(bytes);
  if (!info.ok()) return info.status().WithContext(file.string());
  return info;
}

}  // namespace px
