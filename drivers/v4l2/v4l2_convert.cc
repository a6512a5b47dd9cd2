#include "drivers/v4l2/v4l2_convert.h"

#include <linux/videodev2.h>

#include <cstring>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "drivers/v4l2/v4l2_formats.h"
#include "pipeline/core/size_text.h"

namespace px::v4l2 {
namespace {

// Bytes of pixel data in one row of the first plane.
size_t RowBytes(uint32_t fourcc, int width) {
  switch (fourcc) {
    case V4L2_PIX_FMT_RGB24:
    case V4L2_PIX_FMT_BGR24:
      return static_cast<size_t>(width) * 3;
    case V4L2_PIX_FMT_YUYV:
      return static_cast<size_t>(width) * 2;
    default:  // GREY, NV12 (Y plane), SRGGB8
      return static_cast<size_t>(width);
  }
}

size_t Rows(uint32_t fourcc, int height) {
  return fourcc == V4L2_PIX_FMT_NV12 ? static_cast<size_t>(height) * 3 / 2 : static_cast<size_t>(height);
}

// Copies `rows` rows of `row_bytes` each from a buffer with stride `stride`, packing them.
void CopyRows(const uint8_t* data, size_t stride, size_t rows, size_t row_bytes, uint8_t* out) {
  for (size_t r = 0; r < rows; ++r) std::memcpy(out + r * row_bytes, data + r * stride, row_bytes);
}

Converted DecodeJpeg(const uint8_t* data, size_t bytes_used, const BufferLayout& layout, PixelFormat output) {
  Converted result;
  result.image.format = output;
  result.image.width = layout.width;
  result.image.height = layout.height;
  // libjpeg decodes a truncated JPEG without failing (grey below the cut): look for the
  // end-of-image marker, allowing the zero padding some cameras add after it.
  size_t end = bytes_used;
  while (end > 0 && data[end - 1] == 0) --end;
  if (end < 4 || data[0] != 0xFF || data[1] != 0xD8 || data[end - 2] != 0xFF || data[end - 1] != 0xD9) {
    result.problem = "MJPG frame of " + std::to_string(bytes_used) + " bytes is truncated or not a JPEG (no " +
                     (end >= 2 && data[0] == 0xFF && data[1] == 0xD8 ? "end-of-image" : "start-of-image") + " marker)";
    return result;
  }
  cv::Mat bgr;
  try {
    bgr = cv::imdecode(cv::Mat(1, static_cast<int>(bytes_used), CV_8UC1, const_cast<uint8_t*>(data)), cv::IMREAD_COLOR);
  } catch (const cv::Exception& e) {
    result.problem = std::string("MJPG frame of ") + std::to_string(bytes_used) + " bytes does not decode: " + e.what();
    return result;
  }
  if (bgr.empty()) {
    result.problem = "MJPG frame of " + std::to_string(bytes_used) + " bytes does not decode";
    return result;
  }
  if (bgr.cols != layout.width || bgr.rows != layout.height) {
    result.problem = "MJPG frame decodes to " + SizeText(bgr.cols, bgr.rows) + ", negotiated " +
                     SizeText(layout.width, layout.height);
    return result;
  }
  result.image.bytes.resize(static_cast<size_t>(layout.width) * layout.height * 3);
  cv::Mat out(layout.height, layout.width, CV_8UC3, result.image.bytes.data());
  if (output == PixelFormat::kRgb888) {
    cv::cvtColor(bgr, out, cv::COLOR_BGR2RGB);
  } else {
    bgr.copyTo(out);
  }
  return result;
}

}  // namespace

size_t MinimumFrameBytes(const BufferLayout& layout) {
  if (!PixelFormatForFourcc(layout.fourcc)) return 0;
  const size_t rows = Rows(layout.fourcc, layout.height);
  if (rows == 0) return 0;
  return (rows - 1) * layout.bytes_per_line + RowBytes(layout.fourcc, layout.width);
}

Converted ConvertBuffer(const uint8_t* data, size_t bytes_used, const BufferLayout& layout, PixelFormat output) {
  if (layout.fourcc == V4L2_PIX_FMT_MJPEG) return DecodeJpeg(data, bytes_used, layout, output);

  Converted result;
  result.image.format = output;
  result.image.width = layout.width;
  result.image.height = layout.height;
  const std::optional<PixelFormat> native = PixelFormatForFourcc(layout.fourcc);
  if (!native) {
    result.problem = "fourcc " + FourccName(layout.fourcc) + " cannot be read";
    return result;
  }
  const size_t needed = MinimumFrameBytes(layout);
  if (bytes_used < needed) {
    result.problem = "short buffer: " + std::to_string(bytes_used) + " bytes, a " +
                     SizeText(layout.width, layout.height) + " " + FourccName(layout.fourcc) + " frame needs " +
                     std::to_string(needed);
    return result;
  }
  const size_t row_bytes = RowBytes(layout.fourcc, layout.width);
  const size_t rows = Rows(layout.fourcc, layout.height);
  result.image.bytes.resize(row_bytes * rows);
  CopyRows(data, layout.bytes_per_line, rows, row_bytes, result.image.bytes.data());
  const bool swap = (*native == PixelFormat::kRgb888 && output == PixelFormat::kBgr888) ||
                    (*native == PixelFormat::kBgr888 && output == PixelFormat::kRgb888);
  if (swap) {
    cv::Mat image(layout.height, layout.width, CV_8UC3, result.image.bytes.data());
    cv::cvtColor(image, image, cv::COLOR_RGB2BGR);  // the same swap either way
  } else if (*native != output) {
    result.problem = "cannot convert " + FourccName(layout.fourcc) + " to " + std::string(PixelFormatName(output));
  }
  return result;
}

}  // namespace px::v4l2
