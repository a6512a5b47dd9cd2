// Where an output pixel's ray meets each source view's image, for the blend's blind-view rule
// (ALGORITHM.md section 5): a view whose image does not hold the point where another view puts a
// nearer surface has seen nothing in front of its own surface there, so it has no say against it.
#pragma once

#include <vector>

#include "pipeline/core/camera_model.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/render/layered_scene.h"

namespace px::render {

// The source pixel of output pixel (x, y) at output depth z: (u, v, w) = z B (x, y, 1) + a, then
// (u / w, v / w).
struct RayInView {
  float b[9] = {};  // row-major
  float a[3] = {};
  float width = 0, height = 0;

  // Whether the view's image holds the point, at least `margin_px` inside its border (in front of
  // the view).
  bool Holds(float x, float y, float z, float margin_px) const {
    const float u = z * (b[0] * x + b[1] * y + b[2]) + a[0];
    const float v = z * (b[3] * x + b[4] * y + b[5]) + a[1];
    const float w = z * (b[6] * x + b[7] * y + b[8]) + a[2];
    if (!(w > 0)) return false;
    const float lo = margin_px - 0.5f;
    return u >= lo * w && v >= lo * w && u <= (width - 0.5f - margin_px) * w && v <= (height - 0.5f - margin_px) * w;
  }
};

// One per scene view (LayeredScene::views() order) for an output camera.
std::vector<RayInView> RaysInViews(const LayeredScene& scene, const CameraModel& camera, const Rigid3& cam_from_world);

}  // namespace px::render
