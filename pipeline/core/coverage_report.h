// How many input pixels a virtual view lacks, before any hole filling (paper 4.2.1). Produced by
// the renderer (pipeline/render/scene_renderer.h), used by the direction stage to tell valid
// viewpoints (H(V) < 2) and to measure parallax; it lives in core so direction need not depend
// on render.
#pragma once

#include <functional>

#include "pipeline/core/camera_model.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/status.h"

namespace px {

struct CoverageReport {
  double hole_ratio = 0;  // fraction of output pixels that no source covered
  double hole_score = 0;  // H(V) = sum over hole pixels of d(p)^k / (w * h), k = 3; valid when < 2
  int width = 0;          // the size it was measured at (H(V) depends on it: d scales with size)
  int height = 0;
};

// What the direction stage calls to measure a candidate viewpoint (the renderer's Coverage()).
using CoverageFunction =
    std::function<StatusOr<CoverageReport>(const CameraModel& camera, const Rigid3& cam_from_world)>;

}  // namespace px
