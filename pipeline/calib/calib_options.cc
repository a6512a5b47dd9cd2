#include "pipeline/calib/calib_options.h"

#include <string>

namespace px {

Status CalibOptions::Validate() const {
  if (interpolation != Interpolation::kLinear && interpolation != Interpolation::kCubic) {
    return InvalidArgumentError("calib options: interpolation = " + std::to_string(static_cast<int>(interpolation)) +
                                " is not linear (0) or cubic (1)");
  }
  return OkStatus();
}

}  // namespace px
