#include "pipeline/core/rig_calibration.h"

#include <cmath>
#include <sstream>

namespace px {

Status RigCalibration::Validate() const {
  if (lenses.empty()) return InvalidArgumentError("rig calibration '" + rig_name + "' has no lenses");
  if (lattice.rows > 0) {
    PX_RETURN_IF_ERROR(lattice.Validate().WithContext("rig calibration '" + rig_name + "'"));
    if (lattice.NumViews() != NumViews()) {
      return InvalidArgumentError("rig calibration '" + rig_name + "': lattice has " +
                                  std::to_string(lattice.NumViews()) + " tiles but " + std::to_string(NumViews()) +
                                  " lenses are calibrated");
    }
  }
  for (int i = 0; i < NumViews(); ++i) {
    const LensCalibration& lens = lenses[i];
    PX_RETURN_IF_ERROR(lens.camera.Validate().WithContext("lens " + std::to_string(i)));
    if (lattice.rows > 0) {
      const cv::Rect& rect = lattice.tiles[i].rect;
      if (rect.width != lens.camera.width || rect.height != lens.camera.height) {
        std::ostringstream error;
        error << "lens " << i << ": intrinsics are for " << lens.camera.width << "x" << lens.camera.height
              << " but its tile is " << rect.width << "x" << rect.height;
        return InvalidArgumentError(error.str());
      }
    }
    if (!lens.cam_from_rig.translation.allFinite() || !lens.cam_from_rig.rotation.coeffs().allFinite()) {
      return InvalidArgumentError("lens " + std::to_string(i) + ": pose is not finite");
    }
  }
  if (!(nominal_depth_min_m > 0 && nominal_depth_max_m > nominal_depth_min_m)) {
    std::ostringstream error;
    error << "rig calibration '" << rig_name << "': depth range [" << nominal_depth_min_m << ", " << nominal_depth_max_m
          << "] m is not positive and increasing";
    return InvalidArgumentError(error.str());
  }
  return OkStatus();
}

}  // namespace px
