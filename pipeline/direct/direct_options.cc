#include "pipeline/direct/direct_options.h"

#include <cmath>
#include <sstream>

#include "pipeline/direct/taxonomy.h"

namespace px {

namespace {

bool InRange(double value, double low, double high) { return std::isfinite(value) && value >= low && value <= high; }

Status RangeError(const std::string& field, double value, const std::string& range) {
  std::ostringstream text;
  text << field << ": " << value << " is outside " << range;
  return InvalidArgumentError(text.str());
}

}  // namespace

bool IsKnownMove(const std::string& move) {
  return move == "auto" || move == "dolly_zoom" || move == "morph" || move == "pan_zoom_2d" ||
         direct::ParseMove(move).ok();
}

std::string KnownMovesText() {
  std::string text = "auto, dolly_zoom, morph, pan_zoom_2d";
  for (direct::Move move : direct::AllMoves()) text += ", " + std::string(direct::MoveName(move));
  return text;
}

std::string KnownEffectsText() {
  std::string text = "auto";
  for (direct::Effect effect : direct::AllEffects()) text += ", " + std::string(direct::EffectName(effect));
  return text;
}

Status FaceDetectionOptions::Validate() const {
  if (!(scale_factor > 1 && scale_factor <= 2)) return RangeError("direct.faces.scale_factor", scale_factor, "(1, 2]");
  if (min_neighbors < 1 || min_neighbors > 30)
    return RangeError("direct.faces.min_neighbors", min_neighbors, "[1, 30]");
  if (min_face_px < 8 || min_face_px > 1024) return RangeError("direct.faces.min_face_px", min_face_px, "[8, 1024]");
  if (upscale_below_px < 0 || upscale_below_px > 4096) {
    return RangeError("direct.faces.upscale_below_px", upscale_below_px, "[0, 4096]");
  }
  if (!(min_face_width_m > 0 && max_face_width_m > min_face_width_m && std::isfinite(max_face_width_m))) {
    return InvalidArgumentError("direct.faces.min_face_width_m " + std::to_string(min_face_width_m) +
                                " and max_face_width_m " + std::to_string(max_face_width_m) +
                                " must satisfy 0 < min < max");
  }
  if (max_subjects < 0 || max_subjects > 8) return RangeError("direct.faces.max_subjects", max_subjects, "[0, 8]");
  return OkStatus();
}

Status ViewpointSearchOptions::Validate() const {
  if (grid_size < 2 || grid_size > 64) return RangeError("direct.search.grid_size", grid_size, "[2, 64]");
  if (!InRange(grid_extent, 1, 8)) return RangeError("direct.search.grid_extent", grid_extent, "[1, 8]");
  if (!(valid_hole_score > 0 && valid_hole_score <= 1000)) {
    return RangeError("direct.search.valid_hole_score", valid_hole_score, "(0, 1000]");
  }
  if (!(search_scale > 0 && search_scale <= 1)) return RangeError("direct.search.search_scale", search_scale, "(0, 1]");
  if (!(verify_scale > 0 && verify_scale <= 1)) return RangeError("direct.search.verify_scale", verify_scale, "(0, 1]");
  if (splat_stride < 0 || splat_stride > 64) return RangeError("direct.search.splat_stride", splat_stride, "[0, 64]");
  if (num_longest < 1 || num_longest > 1000) return RangeError("direct.search.num_longest", num_longest, "[1, 1000]");
  if (verify_frames < 2 || verify_frames > 100) {
    return RangeError("direct.search.verify_frames", verify_frames, "[2, 100]");
  }
  if (!(z_first_step > 0 && z_first_step <= 1)) {
    return RangeError("direct.search.z_first_step", z_first_step, "(0, 1]");
  }
  if (!(z_precision > 0 && z_precision <= z_first_step)) {
    return RangeError("direct.search.z_precision", z_precision, "(0, z_first_step]");
  }
  if (!(max_forward > 0 && max_forward < 1)) return RangeError("direct.search.max_forward", max_forward, "(0, 1)");
  if (!(max_back > 0 && max_back <= 10)) return RangeError("direct.search.max_back", max_back, "(0, 10]");
  if (!(max_enlargement >= 1 && max_enlargement <= 16)) {
    return RangeError("direct.search.max_enlargement", max_enlargement, "[1, 16]");
  }
  return OkStatus();
}

Status DirectOptions::Validate() const {
  if (!IsKnownMove(move)) {
    return InvalidArgumentError("direct.move: unknown move \"" + move + "\", want one of " + KnownMovesText());
  }
  if (effect != "auto" && !direct::ParseEffect(effect).ok()) {
    return InvalidArgumentError("direct.effect: unknown effect \"" + effect + "\", want one of " + KnownEffectsText());
  }
  if (!(duration_s > 0 && duration_s <= 60)) return RangeError("direct.duration_s", duration_s, "(0, 60]");
  if (!(fps > 0 && fps <= 240)) return RangeError("direct.fps", fps, "(0, 240]");
  for (size_t i = 0; i < subject_boxes_px.size(); ++i) {
    const cv::Rect2d& box = subject_boxes_px[i];
    if (!(box.width > 0 && box.height > 0) || !std::isfinite(box.x) || !std::isfinite(box.y)) {
      std::ostringstream text;
      text << "direct.subject_boxes_px[" << i << "]: " << box.width << "x" << box.height << " at (" << box.x << ", "
           << box.y << ") is not a rectangle";
      return InvalidArgumentError(text.str());
    }
  }
  PX_RETURN_IF_ERROR(timing.Validate().WithContext("direct.timing"));
  PX_RETURN_IF_ERROR(output.Validate().WithContext("direct.output"));
  PX_RETURN_IF_ERROR(faces.Validate());
  PX_RETURN_IF_ERROR(search.Validate());
  if (!InRange(zoom_in, 1, 4)) return RangeError("direct.zoom_in", zoom_in, "[1, 4]");
  if (!InRange(framing_margin, 0, 0.3)) return RangeError("direct.framing_margin", framing_margin, "[0, 0.3]");
  if (!(max_dolly_zoom > 1 && max_dolly_zoom <= 4))
    return RangeError("direct.max_dolly_zoom", max_dolly_zoom, "(1, 4]");
  if (!(max_aperture_m > 0 && max_aperture_m <= 1))
    return RangeError("direct.max_aperture_m", max_aperture_m, "(0, 1]");
  if (!InRange(min_consistent_fraction, 0, 1)) {
    return RangeError("direct.min_consistent_fraction", min_consistent_fraction, "[0, 1]");
  }
  if (!InRange(min_confident_fraction, 0, 1)) {
    return RangeError("direct.min_confident_fraction", min_confident_fraction, "[0, 1]");
  }
  return OkStatus();
}

}  // namespace px
