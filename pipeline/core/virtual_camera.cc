#include "pipeline/core/virtual_camera.h"

#include <cmath>

namespace px {

std::string_view ColorEffectKindName(ColorEffectKind kind) {
  switch (kind) {
    case ColorEffectKind::kSaturation:
      return "saturation";
    case ColorEffectKind::kBrightness:
      return "brightness";
  }
  return "unknown";
}

StatusOr<ColorEffectKind> ParseColorEffectKind(std::string_view name) {
  for (ColorEffectKind kind : {ColorEffectKind::kSaturation, ColorEffectKind::kBrightness}) {
    if (name == ColorEffectKindName(kind)) return kind;
  }
  return InvalidArgumentError("colour effect '" + std::string(name) + "' is not one of saturation, brightness");
}

Status ColorEffect::Validate() const {
  const std::string what = "colour effect " + std::string(ColorEffectKindName(kind));
  if (!std::isfinite(amount) || amount < 0 || amount > 10) {
    return InvalidArgumentError(what + ": amount " + std::to_string(amount) + " is outside [0, 10]");
  }
  if (!region_min_in_world.allFinite() || !region_max_in_world.allFinite() ||
      (region_max_in_world.array() < region_min_in_world.array()).any()) {
    return InvalidArgumentError(what + ": region is not a box (min must be <= max, finite)");
  }
  if (!std::isfinite(falloff_m) || falloff_m <= 0) {
    return InvalidArgumentError(what + ": falloff_m " + std::to_string(falloff_m) + " must be > 0");
  }
  return OkStatus();
}

Status VirtualCamera::Validate() const {
  PX_RETURN_IF_ERROR(camera.Validate().WithContext("virtual camera"));
  if (camera.HasDistortion()) return InvalidArgumentError("virtual camera: must be a pinhole without distortion");
  if (!cam_from_world.rotation.coeffs().allFinite() || !cam_from_world.translation.allFinite()) {
    return InvalidArgumentError("virtual camera: pose is not finite");
  }
  if (!std::isfinite(aperture_m) || aperture_m < 0) {
    return InvalidArgumentError("virtual camera: aperture_m " + std::to_string(aperture_m) + " must be >= 0");
  }
  if (aperture_m > 0 && !(std::isfinite(focus_depth_m) && focus_depth_m > 0)) {
    return InvalidArgumentError("virtual camera: focus_depth_m " + std::to_string(focus_depth_m) +
                                " must be > 0 with an aperture");
  }
  for (const ColorEffect& effect : effects) PX_RETURN_IF_ERROR(effect.Validate().WithContext("virtual camera"));
  return OkStatus();
}

}  // namespace px
