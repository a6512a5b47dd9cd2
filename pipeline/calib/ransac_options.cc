#include "pipeline/calib/ransac_options.h"

#include <cmath>
#include <string>

namespace px::calib {

Status RansacOptions::Validate() const {
  if (!(max_error_px > 0 && max_error_px <= 100)) {
    return InvalidArgumentError("ransac options: max_error_px = " + std::to_string(max_error_px) +
                                " is outside (0, 100]");
  }
  if (!(focal_px > 0 && focal_px <= 1e6)) {
    return InvalidArgumentError("ransac options: focal_px = " + std::to_string(focal_px) + " is outside (0, 1e6]");
  }
  if (max_iterations < 1 || max_iterations > 100000) {
    return InvalidArgumentError("ransac options: max_iterations = " + std::to_string(max_iterations) +
                                " is outside [1, 100000]");
  }
  if (!(confidence > 0 && confidence < 1)) {
    return InvalidArgumentError("ransac options: confidence = " + std::to_string(confidence) + " is outside (0, 1)");
  }
  return OkStatus();
}

double RansacOptions::MaxErrorRad() const { return std::atan(max_error_px / focal_px); }

}  // namespace px::calib
