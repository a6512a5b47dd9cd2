#include "pipeline/core/pixel_format.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <opencv2/imgproc.hpp>

#include "pipeline/core/size_text.h"

namespace px {
namespace {

struct FormatInfo {
  PixelFormat format;
  std::string_view name;
};

constexpr FormatInfo kFormats[] = {
    {PixelFormat::kRgb888, "RGB888"},
    {PixelFormat::kBgr888, "BGR888"},
    {PixelFormat::kGray8, "GRAY8"},
    {PixelFormat::kYuyv, "YUYV"},
    {PixelFormat::kNv12, "NV12"},
    {PixelFormat::kBayerRggb8, "SRGGB8"},
};

uint8_t Clamp8(double v) { return static_cast<uint8_t>(std::clamp(std::lround(v), 0L, 255L)); }

// BT.601 limited range, the inverse of what OpenCV's YUV->BGR conversions assume.
void BgrToYuv(const cv::Vec3b& bgr, double* y, double* u, double* v) {
  const double b = bgr[0], g = bgr[1], r = bgr[2];
  *y = 16.0 + 0.256788 * r + 0.504129 * g + 0.097906 * b;
  *u = 128.0 - 0.148223 * r - 0.290993 * g + 0.439216 * b;
  *v = 128.0 + 0.439216 * r - 0.367788 * g - 0.071427 * b;
}

}  // namespace

std::string_view PixelFormatName(PixelFormat format) {
  for (const auto& info : kFormats) {
    if (info.format == format) return info.name;
  }
  return "UNKNOWN";
}

std::optional<PixelFormat> ParsePixelFormat(std::string_view name) {
  for (const auto& info : kFormats) {
    if (info.name == name) return info.format;
  }
  return std::nullopt;
}

StatusOr<size_t> PackedImageBytes(PixelFormat format, int width, int height) {
  if (width <= 0 || height <= 0) {
    return InvalidArgumentError("image size " + SizeText(width, height) + " is not positive");
  }
  const size_t pixels = static_cast<size_t>(width) * static_cast<size_t>(height);
  switch (format) {
    case PixelFormat::kRgb888:
    case PixelFormat::kBgr888:
      return pixels * 3;
    case PixelFormat::kGray8:
      return pixels;
    case PixelFormat::kYuyv:
      if (width % 2 != 0) return InvalidArgumentError("YUYV needs an even width, got " + SizeText(width, height));
      return pixels * 2;
    case PixelFormat::kNv12:
      if (width % 2 != 0 || height % 2 != 0) {
        return InvalidArgumentError("NV12 needs an even width and height, got " + SizeText(width, height));
      }
      return pixels * 3 / 2;
    case PixelFormat::kBayerRggb8:
      if (width % 2 != 0 || height % 2 != 0) {
        return InvalidArgumentError("SRGGB8 needs an even width and height, got " + SizeText(width, height));
      }
      return pixels;
  }
  return InvalidArgumentError("unknown pixel format");
}

Status RawImage::Validate() const {
  PX_ASSIGN_OR_RETURN(size_t want, PackedImageBytes(format, width, height));
  if (bytes.size() != want) {
    return DataLossError(std::string(PixelFormatName(format)) + " " + SizeText(width, height) + " image has " +
                         std::to_string(bytes.size()) + " bytes, want " + std::to_string(want));
  }
  return OkStatus();
}

StatusOr<cv::Mat> ToBgr(const RawImage& raw) {
  PX_RETURN_IF_ERROR(raw.Validate());
  // The cv::Mat headers below borrow raw.bytes; every branch produces a fresh output.
  auto* data = const_cast<uint8_t*>(raw.bytes.data());
  cv::Mat bgr;
  switch (raw.format) {
    case PixelFormat::kRgb888:
      cv::cvtColor(cv::Mat(raw.height, raw.width, CV_8UC3, data), bgr, cv::COLOR_RGB2BGR);
      break;
    case PixelFormat::kBgr888:
      bgr = cv::Mat(raw.height, raw.width, CV_8UC3, data).clone();
      break;
    case PixelFormat::kGray8:
      cv::cvtColor(cv::Mat(raw.height, raw.width, CV_8UC1, data), bgr, cv::COLOR_GRAY2BGR);
      break;
    case PixelFormat::kYuyv:
      cv::cvtColor(cv::Mat(raw.height, raw.width, CV_8UC2, data), bgr, cv::COLOR_YUV2BGR_YUYV);
      break;
    case PixelFormat::kNv12:
      cv::cvtColor(cv::Mat(raw.height * 3 / 2, raw.width, CV_8UC1, data), bgr, cv::COLOR_YUV2BGR_NV12);
      break;
    case PixelFormat::kBayerRggb8:
      // OpenCV names Bayer patterns by the second row: RGGB is its "BG" pattern.
      cv::cvtColor(cv::Mat(raw.height, raw.width, CV_8UC1, data), bgr, cv::COLOR_BayerBG2BGR_EA);
      break;
  }
  return bgr;
}

StatusOr<RawImage> FromBgr(const cv::Mat& bgr, PixelFormat format) {
  if (bgr.type() != CV_8UC3) return InvalidArgumentError("FromBgr needs a CV_8UC3 image");
  RawImage raw;
  raw.format = format;
  raw.width = bgr.cols;
  raw.height = bgr.rows;
  PX_ASSIGN_OR_RETURN(size_t bytes, PackedImageBytes(format, bgr.cols, bgr.rows));
  raw.bytes.resize(bytes);
  const int w = bgr.cols, h = bgr.rows;
  switch (format) {
    case PixelFormat::kBgr888:
    case PixelFormat::kRgb888: {
      cv::Mat out(h, w, CV_8UC3, raw.bytes.data());
      if (format == PixelFormat::kBgr888) {
        bgr.copyTo(out);
      } else {
        cv::cvtColor(bgr, out, cv::COLOR_BGR2RGB);
      }
      break;
    }
    case PixelFormat::kGray8: {
      cv::Mat out(h, w, CV_8UC1, raw.bytes.data());
      cv::cvtColor(bgr, out, cv::COLOR_BGR2GRAY);
      break;
    }
    case PixelFormat::kYuyv:
      for (int y = 0; y < h; ++y) {
        const auto* row = bgr.ptr<cv::Vec3b>(y);
        uint8_t* out = raw.bytes.data() + static_cast<size_t>(y) * w * 2;
        for (int x = 0; x < w; x += 2) {
          double y0, u0, v0, y1, u1, v1;
          BgrToYuv(row[x], &y0, &u0, &v0);
          BgrToYuv(row[x + 1], &y1, &u1, &v1);
          out[2 * x + 0] = Clamp8(y0);
          out[2 * x + 1] = Clamp8((u0 + u1) / 2);
          out[2 * x + 2] = Clamp8(y1);
          out[2 * x + 3] = Clamp8((v0 + v1) / 2);
        }
      }
      break;
    case PixelFormat::kNv12: {
      uint8_t* luma = raw.bytes.data();
      uint8_t* chroma = raw.bytes.data() + static_cast<size_t>(w) * h;
      for (int y = 0; y < h; y += 2) {
        for (int x = 0; x < w; x += 2) {
          double u_sum = 0, v_sum = 0;
          for (int dy = 0; dy < 2; ++dy) {
            for (int dx = 0; dx < 2; ++dx) {
              double yy, uu, vv;
              BgrToYuv(bgr.at<cv::Vec3b>(y + dy, x + dx), &yy, &uu, &vv);
              luma[static_cast<size_t>(y + dy) * w + x + dx] = Clamp8(yy);
              u_sum += uu;
              v_sum += vv;
            }
          }
          chroma[static_cast<size_t>(y / 2) * w + x] = Clamp8(u_sum / 4);
          chroma[static_cast<size_t>(y / 2) * w + x + 1] = Clamp8(v_sum / 4);
        }
      }
      break;
    }
    case PixelFormat::kBayerRggb8:
      for (int y = 0; y < h; ++y) {
        const auto* row = bgr.ptr<cv::Vec3b>(y);
        uint8_t* out = raw.bytes.data() + static_cast<size_t>(y) * w;
        for (int x = 0; x < w; ++x) {
          // R at even row/even col, B at odd/odd, G elsewhere.
          const int channel = (y % 2 == 0) ? (x % 2 == 0 ? 2 : 1) : (x % 2 == 0 ? 1 : 0);
          out[x] = row[x][channel];
        }
      }
      break;
  }
  return raw;
}

}  // namespace px
