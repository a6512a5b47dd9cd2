#include "pipeline/run/image_set_scale.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "pipeline/core/pixel_format.h"

namespace px {
namespace {

bool NeedsScaling(const Frame& frame, int max_side_px) {
  return frame.status == FrameStatus::kOk && std::max(frame.image.width, frame.image.height) > max_side_px;
}

}  // namespace

std::optional<WorkingImageSet> ImageSetAtWorkingSize(int max_side_px, const FrameSet& shot, const RigCalibration& rig) {
  if (max_side_px <= 0 || shot.kind != FrameSetKind::kImageSet ||
      std::none_of(shot.frames.begin(), shot.frames.end(), [&](const Frame& frame) {
        return NeedsScaling(frame, max_side_px);
      })) {
    return std::nullopt;
  }
  WorkingImageSet out;
  out.capture.kind = shot.kind;
  out.capture.capture_id = shot.capture_id;
  out.rig = rig;
  const bool rig_per_frame = rig.NumViews() == static_cast<int>(shot.frames.size());
  int scaled = 0;
  std::string from, to;
  for (size_t i = 0; i < shot.frames.size(); ++i) {
    const Frame& frame = shot.frames[i];
    StatusOr<cv::Mat> bgr = NeedsScaling(frame, max_side_px) ? ToBgr(frame.image) : StatusOr<cv::Mat>(cv::Mat());
    if (!bgr.ok() || bgr->empty()) {
      out.capture.frames.push_back(frame);
      continue;
    }
    const double factor = static_cast<double>(max_side_px) / std::max(bgr->cols, bgr->rows);
    const cv::Size size(static_cast<int>(std::lround(bgr->cols * factor)),
                        static_cast<int>(std::lround(bgr->rows * factor)));
    cv::Mat small;
    cv::resize(*bgr, small, size, 0, 0, cv::INTER_AREA);
    StatusOr<RawImage> image = FromBgr(small, PixelFormat::kBgr888);
    if (!image.ok()) {
      out.capture.frames.push_back(frame);
      continue;
    }
    Frame working;  // the frame's metadata, its image at the working size
    working.image = std::move(image).value();
    working.sequence = frame.sequence;
    working.timestamp_ns = frame.timestamp_ns;
    working.status = frame.status;
    working.status_detail = frame.status_detail;
    working.focal_length_px = frame.focal_length_px * factor;
    working.focal_length_source = frame.focal_length_source;
    out.capture.frames.push_back(std::move(working));
    if (rig_per_frame) {
      CameraModel& lens = out.rig.lenses[i].camera;
      if (lens.width == bgr->cols && lens.height == bgr->rows) lens = lens.Scaled(factor);
    }
    from = std::to_string(bgr->cols) + "x" + std::to_string(bgr->rows);
    to = std::to_string(size.width) + "x" + std::to_string(size.height);
    ++scaled;
  }
  out.note = "image set: " + std::to_string(scaled) + " of " + std::to_string(shot.frames.size()) +
             " photos scaled to a longer side of " + std::to_string(max_side_px) + " px for processing (the last " +
             from + " -> " + to + "; pipeline image_set_max_side_px)";
  return out;
}

}  // namespace px
