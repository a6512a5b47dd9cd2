#include "sim/faults/frame_damage.h"

#include <algorithm>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>

namespace px::faults {
namespace {

constexpr uint8_t kDarkLevel = 12;       // a covered lens: near black, flat
constexpr uint8_t kNeutralChroma = 128;  // YUV: no colour

}  // namespace

void TruncateFrame(double keep, Frame* frame) {
  const size_t total = frame->image.bytes.size();
  const size_t kept = static_cast<size_t>(keep * static_cast<double>(total));
  frame->image.bytes.resize(kept);
  frame->status = FrameStatus::kCorrupt;
  frame->status_detail =
      "truncated: " + std::to_string(kept) + " of " + std::to_string(total) + " bytes arrived (injected fault)";
}

void GarbleFrame(int count, bool flagged, uint64_t seed, Frame* frame) {
  std::vector<uint8_t>& bytes = frame->image.bytes;
  if (bytes.empty()) return;
  std::mt19937_64 random(seed);
  std::uniform_int_distribution<size_t> offset(0, bytes.size() - 1);
  std::uniform_int_distribution<int> value(1, 255);
  for (int i = 0; i < count; ++i) bytes[offset(random)] ^= static_cast<uint8_t>(value(random));
  if (flagged) {
    frame->status = FrameStatus::kCorrupt;
    frame->status_detail = "garbled: the driver flagged the buffer as damaged (" + std::to_string(count) +
                           " bytes changed, injected fault)";
  }
}

void DropFrame(Frame* frame) {
  frame->image.bytes.clear();
  frame->image.bytes.shrink_to_fit();
  frame->status = FrameStatus::kDropped;
  frame->status_detail = "no buffer arrived for this image (injected fault)";
}

Status BlankRect(const cv::Rect& rect, RawImage* image) {
  PX_RETURN_IF_ERROR(image->Validate().WithContext("blank a tile"));
  const cv::Rect whole(0, 0, image->width, image->height);
  if ((rect & whole) != rect || rect.empty()) {
    return InvalidArgumentError("blank a tile: rect " + std::to_string(rect.x) + "," + std::to_string(rect.y) + " " +
                                std::to_string(rect.width) + "x" + std::to_string(rect.height) + " is not inside the " +
                                std::to_string(image->width) + "x" + std::to_string(image->height) + " frame");
  }
  const int w = image->width;
  const int h = image->height;
  uint8_t* data = image->bytes.data();
  switch (image->format) {
    case PixelFormat::kRgb888:
    case PixelFormat::kBgr888:
      for (int y = rect.y; y < rect.br().y; ++y) {
        std::fill(data + (size_t(y) * w + rect.x) * 3, data + (size_t(y) * w + rect.br().x) * 3, kDarkLevel);
      }
      break;
    case PixelFormat::kGray8:
    case PixelFormat::kBayerRggb8:  // a flat level in every colour site is flat after demosaicing
      for (int y = rect.y; y < rect.br().y; ++y) {
        std::fill(data + size_t(y) * w + rect.x, data + size_t(y) * w + rect.br().x, kDarkLevel);
      }
      break;
    case PixelFormat::kYuyv:  // Y0 U Y1 V: luma on even bytes, chroma on odd ones
      for (int y = rect.y; y < rect.br().y; ++y) {
        for (int x = rect.x & ~1; x < rect.br().x; ++x) {
          data[(size_t(y) * w + x) * 2] = kDarkLevel;
          data[(size_t(y) * w + x) * 2 + 1] = kNeutralChroma;
        }
      }
      break;
    case PixelFormat::kNv12: {
      for (int y = rect.y; y < rect.br().y; ++y) {
        std::fill(data + size_t(y) * w + rect.x, data + size_t(y) * w + rect.br().x, kDarkLevel);
      }
      uint8_t* uv = data + size_t(w) * h;
      for (int y = rect.y / 2; y < (rect.br().y + 1) / 2; ++y) {
        std::fill(uv + size_t(y) * w + (rect.x & ~1),
                  uv + size_t(y) * w + std::min(w, (rect.br().x + 1) & ~1),
                  kNeutralChroma);
      }
      break;
    }
  }
  return OkStatus();
}

Status ReformatFrame(std::optional<PixelFormat> format, int width, int height, Frame* frame) {
  PX_ASSIGN_OR_RETURN(cv::Mat bgr, ToBgr(frame->image));
  const int new_width = width > 0 ? width : frame->image.width;
  const int new_height = height > 0 ? height : frame->image.height;
  if (new_width != bgr.cols || new_height != bgr.rows) {
    cv::Mat resized;
    cv::resize(bgr, resized, cv::Size(new_width, new_height), 0, 0, cv::INTER_AREA);
    bgr = resized;
  }
  StatusOr<RawImage> raw = FromBgr(bgr, format.value_or(frame->image.format));
  if (!raw.ok()) return raw.status().WithContext("reformat");
  frame->image = std::move(raw).value();
  return OkStatus();
}

}  // namespace px::faults
