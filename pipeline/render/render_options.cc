#include "pipeline/render/render_options.h"

#include <sstream>

namespace px {

Status RenderOptions::Validate() const {
  std::ostringstream error;
  if (num_source_views < 1 || num_source_views > 64) {
    error << "render.num_source_views: " << num_source_views << " is outside [1, 64]";
  } else if (!(soft_z_band > 0 && soft_z_band <= 1)) {
    error << "render.soft_z_band: " << soft_z_band << " is outside (0, 1]";
  } else if (!(max_splat_stretch >= 1 && max_splat_stretch <= 10)) {
    error << "render.max_splat_stretch: " << max_splat_stretch << " is outside [1, 10]";
  } else if (hole_fill_radius_px < 1 || hole_fill_radius_px > 16) {
    error << "render.hole_fill_radius_px: " << hole_fill_radius_px << " is outside [1, 16]";
  }
  if (error.str().empty()) return OkStatus();
  return InvalidArgumentError(error.str());
}

}  // namespace px
