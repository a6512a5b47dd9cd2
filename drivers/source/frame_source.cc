#include "drivers/source/frame_source.h"

#include <chrono>

#include "drivers/source/clock.h"

namespace px {

int64_t SteadyClock::NowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

std::string DescribeConfig(const SourceConfig& config) {
  return std::string(PixelFormatName(config.pixel_format)) + " " + std::to_string(config.width) + "x" +
         std::to_string(config.height) + " x" + std::to_string(config.shots);
}

Status CheckFrameSet(const SourceConfig& granted, FrameSet* frames) {
  Status first_problem;
  for (size_t i = 0; i < frames->frames.size(); ++i) {
    Frame& frame = frames->frames[i];
    if (frame.status != FrameStatus::kOk) {
      if (first_problem.ok()) {
        first_problem = DataLossError("frame " + std::to_string(i) + ": " + std::string(FrameStatusName(frame.status)) +
                                      (frame.status_detail.empty() ? "" : " (" + frame.status_detail + ")"));
      }
      continue;
    }
    const RawImage& image = frame.image;
    const bool size_ok =
        (granted.width == 0 || image.width == granted.width) && (granted.height == 0 || image.height == granted.height);
    if (image.format != granted.pixel_format || !size_ok) {
      frame.status = FrameStatus::kWrongFormat;
      frame.status_detail = "got " + std::to_string(image.width) + "x" + std::to_string(image.height) + " " +
                            std::string(PixelFormatName(image.format)) + ", want " + std::to_string(granted.width) +
                            "x" + std::to_string(granted.height) + " " +
                            std::string(PixelFormatName(granted.pixel_format));
    } else if (Status valid = image.Validate(); !valid.ok()) {
      frame.status = FrameStatus::kCorrupt;
      frame.status_detail = valid.message();
    }
    if (frame.status != FrameStatus::kOk && first_problem.ok()) {
      first_problem = DataLossError("frame " + std::to_string(i) + ": " + frame.status_detail);
    }
  }
  if (frames->NumUsableFrames() > 0) return OkStatus();
  if (frames->frames.empty()) return DataLossError("frame set holds no frames");
  return first_problem;
}

}  // namespace px
