// What one clip frame asks of the renderer: the virtual camera (intrinsics and pose), its lens
// (aperture and focus, for depth of field) and the colour-effect layers in force (paper 4.3 and
// 6.1 "Color effects and depth of field"). Produced per frame by pipeline/direct from a camera
// path, consumed by pipeline/render. It lives in core so that neither stage depends on the other.
#pragma once

#include <Eigen/Core>
#include <string>
#include <string_view>
#include <vector>

#include "pipeline/core/camera_model.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/status.h"

namespace px {

enum class ColorEffectKind {
  kSaturation,  // amount: saturation multiplier, 1 = unchanged, 0 = grey, > 1 = more vivid
  kBrightness,  // amount: brightness multiplier, 1 = unchanged, 0 = black
};

std::string_view ColorEffectKindName(ColorEffectKind kind);  // "saturation", "brightness"
StatusOr<ColorEffectKind> ParseColorEffectKind(std::string_view name);

// One effect layer: applied with full strength inside an axis-aligned 3D box of the world, fading
// with a Gaussian of the distance to the box outside it; or, inverted, to everything but the box
// (e.g. "desaturate the background"). Layers are composited in the order given.
struct ColorEffect {
  ColorEffectKind kind = ColorEffectKind::kSaturation;
  double amount = 1.0;
  Eigen::Vector3d region_min_in_world = Eigen::Vector3d::Zero();  // metres
  Eigen::Vector3d region_max_in_world = Eigen::Vector3d::Zero();
  double falloff_m = 0.05;  // Gaussian sigma of the fade outside the box, metres, > 0
  bool invert = false;      // apply to the complement of the region instead

  Status Validate() const;
};

struct VirtualCamera {
  CameraModel camera;  // pinhole (no distortion): output size, focal length, principal point
  Rigid3 cam_from_world;
  // Thin-lens depth of field: aperture diameter in metres (0 = pinhole, everything sharp) and the
  // in-focus depth in metres along the optical axis (used when aperture_m > 0).
  double aperture_m = 0;
  double focus_depth_m = 0;
  std::vector<ColorEffect> effects;

  // Valid camera without distortion, finite pose, aperture >= 0, focus > 0 when aperture > 0,
  // every effect valid. Errors name the field.
  Status Validate() const;
};

}  // namespace px
