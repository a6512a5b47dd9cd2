#include "pipeline/run/image_set_scale.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "pipeline/core/pixel_format.h"

namespace px {

std::string ScaleImageSetToWorkingSize(int max_side_px, FrameSet* capture, RigCalibration* rig) {
  if (max_side_px <= 0 || capture->kind != FrameSetKind::kImageSet) return "";
  const bool rig_per_frame = rig->NumViews() == static_cast<int>(capture->frames.size());
  int scaled = 0;
  std::string from, to;
  for (size_t i = 0; i < capture->frames.size(); ++i) {
    Frame& frame = capture->frames[i];
    const int longer = std::max(frame.image.width, frame.image.height);
    if (frame.status != FrameStatus::kOk || longer <= max_side_px) continue;
    StatusOr<cv::Mat> bgr = ToBgr(frame.image);
    if (!bgr.ok()) continue;
    const double factor = static_cast<double>(max_side_px) / longer;
    const cv::Size size(static_cast<int>(std::lround(bgr->cols * factor)), static_cast<int>(std::lround(bgr->rows * factor)));
    cv::Mat small;
    cv::resize(*bgr, small, size, 0, 0, cv::INTER_AREA);
    StatusOr<RawImage> image = FromBgr(small, PixelFormat::kBgr888);
    if (!image.ok()) continue;
    if (rig_per_frame) {
      CameraModel& lens = rig->lenses[i].camera;
      if (lens.width == bgr->cols && lens.height == bgr->rows) lens = lens.Scaled(factor);
    }
    from = std::to_string(frame.image.width) + "x" + std::to_string(frame.image.height);
    to = std::to_string(size.width) + "x" + std::to_string(size.height);
    frame.image = std::move(image).value();
    frame.focal_length_px *= factor;
    ++scaled;
  }
  if (scaled == 0) return "";
  return "image set: " + std::to_string(scaled) + " of " + std::to_string(capture->frames.size()) + " photos scaled to " +
         "a longer side of " + std::to_string(max_side_px) + " px for processing (the last " + from + " -> " + to +
         "; pipeline image_set_max_side_px)";
}

}  // namespace px
