#include "pipeline/lattice/lattice_options.h"

#include <cmath>

#include "pipeline/core/option_range.h"

namespace px {

Status LatticeOptions::Validate() const {
  if (max_tiles_per_axis < 2 || max_tiles_per_axis > 16) {
    return OptionOutOfRange("lattice options", "max_tiles_per_axis", max_tiles_per_axis, "[2, 16]");
  }
  if (rows < 0 || rows > max_tiles_per_axis)
    return OptionOutOfRange("lattice options", "rows", rows, "[0, max_tiles_per_axis]");
  if (cols < 0 || cols > max_tiles_per_axis)
    return OptionOutOfRange("lattice options", "cols", cols, "[0, max_tiles_per_axis]");
  if (!(max_rotation_deg >= 0 && max_rotation_deg <= 10)) {
    return OptionOutOfRange("lattice options", "max_rotation_deg", max_rotation_deg, "[0, 10]");
  }
  if (!(max_size_spread > 0 && max_size_spread <= 1))
    return OptionOutOfRange("lattice options", "max_size_spread", max_size_spread, "(0, 1]");
  if (!(min_gap_z >= 2 && min_gap_z <= 50))
    return OptionOutOfRange("lattice options", "min_gap_z", min_gap_z, "[2, 50]");
  if (!(prior_search_px >= 2 && prior_search_px <= 200)) {
    return OptionOutOfRange("lattice options", "prior_search_px", prior_search_px, "[2, 200]");
  }
  if (!(min_confidence >= 0 && min_confidence <= 1))
    return OptionOutOfRange("lattice options", "min_confidence", min_confidence, "[0, 1]");
  if (working_size_px < 256 || working_size_px > 4096) {
    return OptionOutOfRange("lattice options", "working_size_px", working_size_px, "[256, 4096]");
  }
  return OkStatus();
}

}  // namespace px
