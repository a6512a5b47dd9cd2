#include "pipeline/depth/plane_sweep_options.h"

#include <cmath>
#include <sstream>

#include "pipeline/core/option_range.h"

namespace px {

Status PlaneSweepOptions::Validate() const {
  if (!(min_depth_m >= 0) || !std::isfinite(min_depth_m))
    return OptionOutOfRange("plane sweep options", "min_depth_m", min_depth_m, "[0, inf)");
  if (!(max_depth_m >= 0) || !std::isfinite(max_depth_m))
    return OptionOutOfRange("plane sweep options", "max_depth_m", max_depth_m, "[0, inf)");
  if (min_depth_m > 0 && max_depth_m > 0 && !(max_depth_m > min_depth_m)) {
    std::ostringstream error;
    error << "plane sweep options: max_depth_m = " << max_depth_m
          << " is not greater than min_depth_m = " << min_depth_m;
    return InvalidArgumentError(error.str());
  }
  if (num_planes < 2 || num_planes > 1024)
    return OptionOutOfRange("plane sweep options", "num_planes", num_planes, "[2, 1024]");
  if (window_radius_px < 1 || window_radius_px > 15)
    return OptionOutOfRange("plane sweep options", "window_radius_px", window_radius_px, "[1, 15]");
  if (num_neighbors < 1 || num_neighbors > 16)
    return OptionOutOfRange("plane sweep options", "num_neighbors", num_neighbors, "[1, 16]");
  if (!(working_scale > 0 && working_scale <= 1))
    return OptionOutOfRange("plane sweep options", "working_scale", working_scale, "(0, 1]");
  if (cost_filter_radius_px < 0 || cost_filter_radius_px > 15) {
    return OptionOutOfRange("plane sweep options", "cost_filter_radius_px", cost_filter_radius_px, "[0, 15]");
  }
  if (!(cost_filter_eps >= 1e-6 && cost_filter_eps <= 1))
    return OptionOutOfRange("plane sweep options", "cost_filter_eps", cost_filter_eps, "[1e-6, 1]");
  if (!(min_texture_stddev >= 0 && min_texture_stddev <= 0.5)) {
    return OptionOutOfRange("plane sweep options", "min_texture_stddev", min_texture_stddev, "[0, 0.5]");
  }
  if (speckle_max_size_px < 0 || speckle_max_size_px > 1000000) {
    return OptionOutOfRange("plane sweep options", "speckle_max_size_px", speckle_max_size_px, "[0, 1000000]");
  }
  if (!(fill_confidence >= 0 && fill_confidence <= 1))
    return OptionOutOfRange("plane sweep options", "fill_confidence", fill_confidence, "[0, 1]");
  if (num_threads < 0 || num_threads > 256)
    return OptionOutOfRange("plane sweep options", "num_threads", num_threads, "[0, 256]");
  return OkStatus();
}

PlaneSweepOptions PlaneSweepOptions::WithDefaultDepthRange(double nominal_min_m, double nominal_max_m) const {
  PlaneSweepOptions resolved = *this;
  if (resolved.min_depth_m == 0) resolved.min_depth_m = nominal_min_m;
  if (resolved.max_depth_m == 0) resolved.max_depth_m = nominal_max_m;
  return resolved;
}

}  // namespace px
