#include "capture/frame_file.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "pipeline/core/size_text.h"
#include "pipeline/io/image_file.h"

namespace px::capture {
namespace {

constexpr std::array<uint8_t, 8> kPngSignature = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};

// zlib level 1 with the RLE strategy: on a 12 MP noisy gradient it encodes fastest of the
// compressing settings (about 0.7 s on one core, half the size of level 0; level 3 takes over
// twice as long for a slightly larger file).
constexpr int kPngCompressionLevel = 1;

int ChannelsOf(PixelFormat format) { return format == PixelFormat::kGray8 ? 1 : 3; }

}  // namespace

bool PngCanHold(PixelFormat format) {
  return format == PixelFormat::kRgb888 || format == PixelFormat::kBgr888 || format == PixelFormat::kGray8;
}

FrameFileType ChooseFrameFileType(const RawImage& image, bool has_jpeg) {
  if (!image.Validate().ok()) return FrameFileType::kRaw;
  if (has_jpeg && image.format == PixelFormat::kRgb888) return FrameFileType::kJpeg;
  return PngCanHold(image.format) ? FrameFileType::kPng : FrameFileType::kRaw;
}

std::string_view FrameFileExtension(FrameFileType type) {
  switch (type) {
    case FrameFileType::kPng:
      return ".png";
    case FrameFileType::kJpeg:
      return ".jpg";
    case FrameFileType::kRaw:
      break;
  }
  return ".raw";
}

StatusOr<FrameFileType> FrameFileTypeOf(std::string_view file_name) {
  auto ends_with = [&](std::string_view suffix) {
    return file_name.size() > suffix.size() && file_name.substr(file_name.size() - suffix.size()) == suffix;
  };
  if (ends_with(".png")) return FrameFileType::kPng;
  if (ends_with(".jpg")) return FrameFileType::kJpeg;
  if (ends_with(".raw")) return FrameFileType::kRaw;
  return InvalidArgumentError("'" + std::string(file_name) + "' is none of a .png, .jpg or .raw file");
}

StatusOr<std::vector<uint8_t>> EncodeFrameFile(const RawImage& image, FrameFileType type) {
  if (type == FrameFileType::kRaw) return image.bytes;
  if (type == FrameFileType::kJpeg)
    return InvalidArgumentError("a JPEG frame file is the camera's own, not encoded here");
  if (!PngCanHold(image.format)) {
    return InvalidArgumentError(std::string(PixelFormatName(image.format)) + " cannot be stored as PNG");
  }
  PX_RETURN_IF_ERROR(image.Validate());
  try {
    // The header borrows the bytes; imencode only reads them.
    const cv::Mat packed(image.height,
                         image.width,
                         ChannelsOf(image.format) == 1 ? CV_8UC1 : CV_8UC3,
                         const_cast<uint8_t*>(image.bytes.data()));
    // imencode takes BGR: RGB bytes are swapped (into a new buffer; the image is const) so the
    // PNG shows true colours in any viewer.
    cv::Mat to_encode;
    if (image.format == PixelFormat::kRgb888) {
      cv::cvtColor(packed, to_encode, cv::COLOR_RGB2BGR);
    } else {
      to_encode = packed;
    }
    std::vector<uint8_t> file;
    if (!cv::imencode(".png",
                      to_encode,
                      file,
                      {cv::IMWRITE_PNG_COMPRESSION,
                       kPngCompressionLevel,
                       cv::IMWRITE_PNG_STRATEGY,
                       cv::IMWRITE_PNG_STRATEGY_RLE})) {
      return InternalError("PNG encoder refused a " + SizeText(image.width, image.height) + " image");
    }
    return file;
  } catch (const cv::Exception& e) {
    return InternalError(std::string("PNG encoding failed: ") + e.what());
  }
}

StatusOr<std::vector<uint8_t>> DecodePngFrame(std::span<const uint8_t> file,
                                              PixelFormat format,
                                              int width,
                                              int height) {
  if (!PngCanHold(format)) {
    return InvalidArgumentError(std::string(PixelFormatName(format)) + " frames are stored as .raw, not PNG");
  }
  if (file.size() < kPngSignature.size() || !std::equal(kPngSignature.begin(), kPngSignature.end(), file.begin())) {
    return DataLossError("truncated or not a PNG (no PNG signature)");
  }
  cv::Mat decoded;
  try {
    const cv::Mat encoded(1, static_cast<int>(file.size()), CV_8UC1, const_cast<uint8_t*>(file.data()));
    decoded = cv::imdecode(encoded, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    return DataLossError(std::string("truncated or not a PNG (") + e.what() + ")");
  }
  if (decoded.empty()) return DataLossError("truncated or not a PNG (the decoder gave up)");
  if (decoded.depth() != CV_8U || decoded.channels() != ChannelsOf(format)) {
    return DataLossError("decodes to " + std::to_string(decoded.channels()) + " channel(s) of " +
                         (decoded.depth() == CV_8U ? "8" : "16 or more") + " bits, " +
                         std::string(PixelFormatName(format)) + " needs " + std::to_string(ChannelsOf(format)) +
                         " channel(s) of 8 bits");
  }
  if (decoded.cols != width || decoded.rows != height) {
    return DataLossError("decodes to " + SizeText(decoded.cols, decoded.rows) + ", the manifest says " +
                         SizeText(width, height));
  }
  std::vector<uint8_t> bytes(static_cast<size_t>(width) * height * ChannelsOf(format));
  cv::Mat packed;
  try {
    packed = cv::Mat(height, width, decoded.type(), bytes.data());
    if (format == PixelFormat::kRgb888) {
      cv::cvtColor(decoded, packed, cv::COLOR_BGR2RGB);
    } else {
      decoded.copyTo(packed);
    }
  } catch (const cv::Exception& e) {
    return InternalError(std::string("PNG unpacking failed: ") + e.what());
  }
  // cvtColor / copyTo must have written into our buffer, not reallocated.
  PX_CHECK(packed.data == bytes.data()) << "decoded frame was not unpacked in place";
  return bytes;
}

StatusOr<std::vector<uint8_t>> DecodeJpegFrame(std::span<const uint8_t> file, int width, int height) {
  StatusOr<cv::Mat> bgr = DecodeImageBytes(file, "JPEG frame");
  if (!bgr.ok()) return DataLossError("truncated or not a JPEG (" + bgr.status().message() + ")");
  if (bgr->cols != width || bgr->rows != height) {
    return DataLossError("decodes to " + SizeText(bgr->cols, bgr->rows) + ", the manifest says " +
                         SizeText(width, height));
  }
  cv::Mat rgb;
  cv::cvtColor(*bgr, rgb, cv::COLOR_BGR2RGB);
  return std::vector<uint8_t>(rgb.data, rgb.data + rgb.total() * rgb.elemSize());
}

}  // namespace px::capture
