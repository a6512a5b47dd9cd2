#include "pipeline/render/render_options.h"

#include <sstream>
#include <string>

namespace px {

std::string_view RenderQualityName(RenderQuality quality) {
  switch (quality) {
    case RenderQuality::kPreview:
      return "preview";
    case RenderQuality::kOffline:
      return "offline";
  }
  return "unknown";
}

StatusOr<RenderQuality> ParseRenderQuality(std::string_view name) {
  for (RenderQuality quality : {RenderQuality::kPreview, RenderQuality::kOffline}) {
    if (name == RenderQualityName(quality)) return quality;
  }
  return InvalidArgumentError("render quality '" + std::string(name) + "' is not one of preview, offline");
}

Status RenderOptions::Validate() const {
  std::ostringstream error;
  if (!(soft_z_gamma_fraction > 0 && soft_z_gamma_fraction < 0.5)) {
    error << "render.soft_z_gamma_fraction: " << soft_z_gamma_fraction << " is outside (0, 0.5)";
  } else if (!(depth_range_m >= 0 && depth_range_m <= 1e4)) {
    error << "render.depth_range_m: " << depth_range_m << " is outside [0, 1e4]";
  } else if (!(covered_alpha > 0 && covered_alpha <= 1)) {
    error << "render.covered_alpha: " << covered_alpha << " is outside (0, 1]";
  } else if (!(viewing_weight_exponent > 0 && viewing_weight_exponent <= 1)) {
    error << "render.viewing_weight_exponent: " << viewing_weight_exponent << " is outside (0, 1]";
  } else if (!(border_holes.spread >= 0 && border_holes.spread <= 4)) {
    error << "render.border_holes.spread: " << border_holes.spread << " is outside [0, 4]";
  } else if (hole_window_radius_px < 1 || hole_window_radius_px > 8) {
    error << "render.hole_window_radius_px: " << hole_window_radius_px << " is outside [1, 8]";
  } else if (inpaint_patch_radius_px < 1 || inpaint_patch_radius_px > 6) {
    error << "render.inpaint_patch_radius_px: " << inpaint_patch_radius_px << " is outside [1, 6]";
  } else if (inpaint_window_radius_px < 4 || inpaint_window_radius_px > 1000) {
    error << "render.inpaint_window_radius_px: " << inpaint_window_radius_px << " is outside [4, 1000]";
  } else if (aperture_samples < 1 || aperture_samples > 256) {
    error << "render.aperture_samples: " << aperture_samples << " is outside [1, 256]";
  } else if (!(seam_skirts.max_step >= 0 && seam_skirts.max_step < 1)) {
    error << "render.seam_skirts.max_step: " << seam_skirts.max_step << " is outside [0, 1)";
  } else if (!(seam_skirts.min_step >= 0 &&
               (seam_skirts.max_step == 0 || seam_skirts.min_step < seam_skirts.max_step))) {
    error << "render.seam_skirts.min_step: " << seam_skirts.min_step << " is outside [0, max_step)";
  } else if (!(seam_skirts.weight > 0 && seam_skirts.weight <= 1)) {
    error << "render.seam_skirts.weight: " << seam_skirts.weight << " is outside (0, 1]";
  } else if (!(texture_stretch.fade_from >= 0 && texture_stretch.fade_from <= 100)) {
    error << "render.texture_stretch.fade_from: " << texture_stretch.fade_from << " is outside [0, 100]";
  } else if (!(texture_stretch.fade_from == 0 || texture_stretch.fade_to > texture_stretch.fade_from)) {
    error << "render.texture_stretch.fade_to: " << texture_stretch.fade_to << " is not above fade_from";
  } else if (!(max_output_pixels >= 1 && max_output_pixels <= 1e9)) {
    error << "render.max_output_pixels: " << max_output_pixels << " is outside [1, 1e9]";
  }
  if (error.str().empty()) return consistent_blend.Validate();
  return InvalidArgumentError(error.str());
}

Status ConsistentBlendOptions::Validate() const {
  std::ostringstream error;
  if (!(free_space_px > 0 && free_space_px <= 100)) {
    error << "render.consistent_blend.free_space_px: " << free_space_px << " is outside (0, 100]";
  } else if (colour_levels < 1 || colour_levels > 255) {
    error << "render.consistent_blend.colour_levels: " << colour_levels << " is outside [1, 255]";
  } else if (colour_agree_levels < 0 || colour_agree_levels > 255) {
    error << "render.consistent_blend.colour_agree_levels: " << colour_agree_levels << " is outside [0, 255]";
  } else if (colour_apart_levels < 0 || colour_apart_levels > 255) {
    error << "render.consistent_blend.colour_apart_levels: " << colour_apart_levels << " is outside [0, 255]";
  } else if (max_neighbours < 1 || max_neighbours > 16) {
    error << "render.consistent_blend.max_neighbours: " << max_neighbours << " is outside [1, 16]";
  } else if (!(dominance_exponent >= 1 && dominance_exponent <= 64)) {
    error << "render.consistent_blend.dominance_exponent: " << dominance_exponent << " is outside [1, 64]";
  }
  if (error.str().empty()) return OkStatus();
  return InvalidArgumentError(error.str());
}

}  // namespace px
