#include "pipeline/direct/plan_camera_path.h"

#include "pipeline/direct/establishing_dolly.h"

namespace px {

StatusOr<CameraPath> PlanCameraPath(const std::vector<View>& views, const std::vector<DepthMap>& depths,
                                    const DirectOptions& options) {
  PX_RETURN_IF_ERROR(options.Validate());
  // Validate() admits only known moves; both lead to the establishing dolly for now.
  PX_ASSIGN_OR_RETURN(CameraPath path, PlanEstablishingDolly(views, depths, options));
  if (options.move == "auto") {
    path.reason = "auto: no subject of interest detected (subject detection is not implemented), so the "
                  "establishing dolly; " + path.reason;
  } else {
    path.reason = "requested: " + path.reason;
  }
  return path;
}

}  // namespace px
