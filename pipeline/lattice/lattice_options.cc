#include "pipeline/lattice/lattice_options.h"

#include <cmath>
#include <sstream>

namespace px {
namespace {

template <typename T>
Status OutOfRange(const char* field, T value, const char* range) {
  std::ostringstream message;
  message << "lattice options: " << field << " " << value << " is outside " << range;
  return InvalidArgumentError(message.str());
}

}  // namespace

Status LatticeOptions::Validate() const {
  if (max_tiles_per_axis < 2 || max_tiles_per_axis > 16) {
    return OutOfRange("max_tiles_per_axis", max_tiles_per_axis, "[2, 16]");
  }
  if (rows < 0 || rows > max_tiles_per_axis) return OutOfRange("rows", rows, "[0, max_tiles_per_axis]");
  if (cols < 0 || cols > max_tiles_per_axis) return OutOfRange("cols", cols, "[0, max_tiles_per_axis]");
  if (!(max_rotation_deg >= 0 && max_rotation_deg <= 10)) {
    return OutOfRange("max_rotation_deg", max_rotation_deg, "[0, 10]");
  }
  if (!(max_size_spread > 0 && max_size_spread <= 1)) return OutOfRange("max_size_spread", max_size_spread, "(0, 1]");
  if (!(min_gap_z >= 2 && min_gap_z <= 50)) return OutOfRange("min_gap_z", min_gap_z, "[2, 50]");
  if (!(prior_search_px >= 2 && prior_search_px <= 200)) {
    return OutOfRange("prior_search_px", prior_search_px, "[2, 200]");
  }
  if (!(min_confidence >= 0 && min_confidence <= 1)) return OutOfRange("min_confidence", min_confidence, "[0, 1]");
  if (working_size_px < 256 || working_size_px > 4096) {
    return OutOfRange("working_size_px", working_size_px, "[256, 4096]");
  }
  return OkStatus();
}

}  // namespace px
