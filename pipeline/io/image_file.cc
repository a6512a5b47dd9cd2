#include "pipeline/io/image_file.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <fstream>
#include <iterator>
#include <new>
#include <opencv2/imgcodecs.hpp>
#include <vector>

#include "pipeline/core/size_text.h"

namespace px {
namespace {

uint32_t BigEndian16(const uint8_t* p) { return (uint32_t{p[0]} << 8) | p[1]; }
uint32_t BigEndian32(const uint8_t* p) { return (BigEndian16(p) << 16) | BigEndian16(p + 2); }
uint32_t LittleEndian16(const uint8_t* p) { return uint32_t{p[0]} | (uint32_t{p[1]} << 8); }
uint32_t LittleEndian24(const uint8_t* p) { return LittleEndian16(p) | (uint32_t{p[2]} << 16); }

bool StartsWith(std::span<const uint8_t> bytes, const char* magic, size_t offset = 0) {
  const size_t n = std::strlen(magic);
  return bytes.size() >= offset + n && std::memcmp(bytes.data() + offset, magic, n) == 0;
}

bool IsJpeg(std::span<const uint8_t> bytes) { return bytes.size() >= 3 && bytes[0] == 0xFF && bytes[1] == 0xD8; }

// The JPEG's frame header (SOF0..SOF15 but DHT, JPG and DAC), found by walking the segments.
StatusOr<ImageHeaderSize> JpegSize(std::span<const uint8_t> bytes) {
  size_t at = 2;
  while (at + 4 <= bytes.size()) {
    if (bytes[at] != 0xFF) return DataLossError("a JPEG whose segments are garbled before its frame header");
    const uint8_t marker = bytes[at + 1];
    if (marker == 0xFF) {  // fill byte
      ++at;
      continue;
    }
    if (marker == 0x01 || (marker >= 0xD0 && marker <= 0xD7)) {  // no length
      at += 2;
      continue;
    }
    if (marker == 0xDA || marker == 0xD9) break;  // scan data or end, and no frame header yet
    const uint32_t length = BigEndian16(&bytes[at + 2]);
    const bool frame = marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
    if (frame) {
      if (at + 9 > bytes.size() || length < 7) break;
      return ImageHeaderSize{BigEndian16(&bytes[at + 7]), BigEndian16(&bytes[at + 5])};
    }
    at += 2 + length;
  }
  return DataLossError("a JPEG with no frame header (truncated or not a JPEG)");
}

StatusOr<ImageHeaderSize> WebpSize(std::span<const uint8_t> bytes) {
  if (bytes.size() < 30) return DataLossError("a WebP file too short to hold its header");
  const uint8_t* chunk = bytes.data() + 12;
  const uint8_t* data = chunk + 8;
  if (StartsWith(bytes, "VP8X", 12)) return ImageHeaderSize{LittleEndian24(data + 4) + 1, LittleEndian24(data + 7) + 1};
  if (StartsWith(bytes, "VP8 ", 12)) {
    return ImageHeaderSize{LittleEndian16(data + 6) & 0x3FFF, LittleEndian16(data + 8) & 0x3FFF};
  }
  if (StartsWith(bytes, "VP8L", 12)) {
    const uint32_t bits = LittleEndian16(data + 1) | (LittleEndian16(data + 3) << 16);
    return ImageHeaderSize{(bits & 0x3FFF) + 1, ((bits >> 14) & 0x3FFF) + 1};
  }
  return DataLossError("a WebP file whose first chunk is none of VP8, VP8L, VP8X");
}

}  // namespace

StatusOr<ImageHeaderSize> ReadImageHeaderSize(std::span<const uint8_t> bytes) {
  if (IsJpeg(bytes)) return JpegSize(bytes);
  if (StartsWith(bytes, "\x89PNG\r\n\x1a\n")) {
    if (bytes.size() < 24 || !StartsWith(bytes, "IHDR", 12)) return DataLossError("a PNG with no IHDR header");
    return ImageHeaderSize{BigEndian32(&bytes[16]), BigEndian32(&bytes[20])};
  }
  if (StartsWith(bytes, "GIF87a") || StartsWith(bytes, "GIF89a")) {
    if (bytes.size() < 10) return DataLossError("a GIF too short to hold its header");
    return ImageHeaderSize{LittleEndian16(&bytes[6]), LittleEndian16(&bytes[8])};
  }
  if (StartsWith(bytes, "RIFF") && StartsWith(bytes, "WEBP", 8)) return WebpSize(bytes);
  return DataLossError("not a JPEG, PNG, GIF or WebP image (by its first bytes)");
}

StatusOr<cv::Mat> DecodeImageBytes(std::span<const uint8_t> bytes,
                                   const std::string& name,
                                   const ImageDecodeOptions& options) {
  StatusOr<ImageHeaderSize> size = ReadImageHeaderSize(bytes);
  if (!size.ok()) return DataLossError(name + ": cannot be decoded: " + size.status().message());
  if (size->width <= 0 || size->height <= 0)
    return DataLossError(name + ": its header claims " + SizeText(size->width, size->height) + " pixels");
  const double pixels = static_cast<double>(size->width) * static_cast<double>(size->height);
  if (pixels > options.max_pixels) {
    return ResourceExhaustedError(name + ": its header claims " + SizeText(size->width, size->height) + " pixels (" +
                                  std::to_string(static_cast<int64_t>(pixels / 1e6)) + " MP), over the limit of " +
                                  std::to_string(static_cast<int64_t>(options.max_pixels / 1e6)) +
                                  " MP; refused before decoding");
  }
  int flags = options.apply_orientation ? cv::IMREAD_COLOR : (cv::IMREAD_COLOR | cv::IMREAD_IGNORE_ORIENTATION);
  if (options.min_longer_side_px > 0 && IsJpeg(bytes)) {
    const int64_t longer = std::max(size->width, size->height);
    const std::array<std::pair<int, int>, 3> reductions = {
        {{8, cv::IMREAD_REDUCED_COLOR_8}, {4, cv::IMREAD_REDUCED_COLOR_4}, {2, cv::IMREAD_REDUCED_COLOR_2}}};
    for (const auto& [factor, reduced_flag] : reductions) {
      if (longer / factor >= options.min_longer_side_px) {
        flags = reduced_flag | (options.apply_orientation ? 0 : cv::IMREAD_IGNORE_ORIENTATION);
        break;
      }
    }
  }
  cv::Mat bgr;
  try {
    const cv::Mat encoded(1, static_cast<int>(bytes.size()), CV_8UC1, const_cast<uint8_t*>(bytes.data()));
    bgr = cv::imdecode(encoded, flags);
  } catch (const cv::Exception& e) {
    return DataLossError(name + ": cannot be decoded (" + e.err + ")");
  } catch (const std::bad_alloc&) {
    return ResourceExhaustedError(name + ": out of memory decoding " + SizeText(size->width, size->height) + " pixels");
  }
  if (bgr.empty()) return DataLossError(name + ": cannot be decoded (truncated or damaged)");
  return bgr;
}

StatusOr<std::vector<uint8_t>> ReadImageFileBytes(const std::filesystem::path& file,
                                                  const ImageDecodeOptions& options) {
  std::error_code ec;
  const uintmax_t file_bytes = std::filesystem::file_size(file, ec);
  // A compressed image is far smaller than its pixels; a file over 3 bytes a pixel allowed is not a photo.
  if (!ec && static_cast<double>(file_bytes) > 3 * options.max_pixels) {
    return ResourceExhaustedError(
        file.string() + ": " + std::to_string(file_bytes / 1000000) + " MB, more than an image of the " +
        std::to_string(static_cast<int64_t>(options.max_pixels / 1e6)) + " MP limit can hold; refused before reading");
  }
  std::ifstream in(file, std::ios::binary);
  if (!in) return NotFoundError(file.string() + ": cannot be opened");
  std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) return DataLossError(file.string() + ": read error");
  return bytes;
}

StatusOr<cv::Mat> DecodeImageFile(const std::filesystem::path& file, const ImageDecodeOptions& options) {
  PX_ASSIGN_OR_RETURN(const std::vector<uint8_t> bytes, ReadImageFileBytes(file, options));
  return DecodeImageBytes(bytes, file.string(), options);
}

}  // namespace px
