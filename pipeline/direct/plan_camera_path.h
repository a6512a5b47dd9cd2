// Chooses the camera move for a scene (paper 4.1) and plans its path (4.2).
#pragma once

#include <vector>

#include "pipeline/core/view.h"
#include "pipeline/direct/camera_path.h"

namespace px {

// options.move "auto": the scene decides. Subject detection is not part of the pipeline yet, so
// every scene counts as having no subject of interest and gets the establishing dolly; the
// path's reason says so. A named move plans that move.
StatusOr<CameraPath> PlanCameraPath(const std::vector<View>& views, const std::vector<DepthMap>& depths,
                                    const DirectOptions& options);

}  // namespace px
