#include "pipeline/run/image_set_scale.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>

#include "pipeline/core/pixel_format.h"
#include "pipeline/run/palette_dither.h"

namespace px {
namespace {

bool NeedsScaling(const Frame& frame, int max_side_px) {
  return max_side_px > 0 && frame.status == FrameStatus::kOk &&
         std::max(frame.image.width, frame.image.height) > max_side_px;
}

// A frame whose few colours suggest a palette (its dither is confirmed on the decoded image).
bool MayBePaletteImage(const Frame& frame) {
  return frame.status == FrameStatus::kOk && CountColoursUpTo(frame.image, kMaxPaletteColours) <= kMaxPaletteColours;
}

}  // namespace

std::optional<WorkingImageSet> ImageSetAtWorkingSize(int max_side_px, const FrameSet& shot, const RigCalibration& rig) {
  if (shot.kind != FrameSetKind::kImageSet) return std::nullopt;
  std::vector<bool> scale(shot.frames.size()), palette(shot.frames.size());
  for (size_t i = 0; i < shot.frames.size(); ++i) {
    scale[i] = NeedsScaling(shot.frames[i], max_side_px);
    palette[i] = MayBePaletteImage(shot.frames[i]);
  }
  if (std::none_of(scale.begin(), scale.end(), [](bool b) { return b; }) &&
      std::none_of(palette.begin(), palette.end(), [](bool b) { return b; })) {
    return std::nullopt;
  }
  WorkingImageSet out;
  out.capture.kind = shot.kind;
  out.capture.capture_id = shot.capture_id;
  out.rig = rig;
  const bool rig_per_frame = rig.NumViews() == static_cast<int>(shot.frames.size());
  int scaled = 0, dedithered = 0;
  double residual_before = 0.0;
  std::string from, to;
  for (size_t i = 0; i < shot.frames.size(); ++i) {
    const Frame& frame = shot.frames[i];
    StatusOr<cv::Mat> bgr = scale[i] || palette[i] ? ToBgr(frame.image) : StatusOr<cv::Mat>(cv::Mat());
    if (!bgr.ok() || bgr->empty()) {
      out.capture.frames.push_back(frame);
      continue;
    }
    cv::Mat working_bgr = *bgr;
    bool changed = false;
    if (palette[i]) {
      cv::Mat without_dither;
      const double residual = PixelScaleResidual(working_bgr, &without_dither);
      if (residual > kDitherResidualLevels) {
        working_bgr = without_dither;
        residual_before = std::max(residual_before, residual);
        ++dedithered;
        changed = true;
      }
    }
    double factor = 1.0;
    if (scale[i]) {
      factor = static_cast<double>(max_side_px) / std::max(bgr->cols, bgr->rows);
      const cv::Size size(static_cast<int>(std::lround(bgr->cols * factor)),
                          static_cast<int>(std::lround(bgr->rows * factor)));
      cv::Mat small;
      cv::resize(working_bgr, small, size, 0, 0, cv::INTER_AREA);
      working_bgr = small;
      from = std::to_string(bgr->cols) + "x" + std::to_string(bgr->rows);
      to = std::to_string(size.width) + "x" + std::to_string(size.height);
      ++scaled;
      changed = true;
    }
    StatusOr<RawImage> image = changed ? FromBgr(working_bgr, PixelFormat::kBgr888) : StatusOr<RawImage>(RawImage{});
    if (!changed || !image.ok()) {
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
    if (rig_per_frame && factor != 1.0) {
      CameraModel& lens = out.rig.lenses[i].camera;
      if (lens.width == bgr->cols && lens.height == bgr->rows) lens = lens.Scaled(factor);
    }
  }
  if (scaled == 0 && dedithered == 0) return std::nullopt;
  std::string note = "image set:";
  if (scaled > 0) {
    note += " " + std::to_string(scaled) + " of " + std::to_string(shot.frames.size()) +
            " photos scaled to a longer side of " + std::to_string(max_side_px) + " px for processing (the last " +
            from + " -> " + to + "; pipeline image_set_max_side_px)";
  }
  if (dedithered > 0) {
    char residual[32];
    std::snprintf(residual, sizeof residual, "%.1f", residual_before);
    note += std::string(scaled > 0 ? ";" : "") + " " + std::to_string(dedithered) + " of " +
            std::to_string(shot.frames.size()) + " frames are palette images (at most " +
            std::to_string(kMaxPaletteColours) + " colours) with a visible dither (up to " + residual +
            " levels at the pixel scale): dither removed";
  }
  out.note = note;
  return out;
}

}  // namespace px
