// The interface every rendering back end implements (paper section 6): one captured scene (views
// with their layered depth, pipeline/core/layered_depth.h) rendered from any virtual camera.
// Back ends: the CPU reference (this folder) and GL on OSMesa or EGL (pipeline/render/gl), which
// must agree with the CPU reference within a stated tolerance. The direction stage searches
// viewpoints through Coverage(); the clip is made with Render().
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <string_view>
#include <vector>

#include "pipeline/core/camera_model.h"
#include "pipeline/core/coverage_report.h"
#include "pipeline/core/layered_depth.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/status.h"
#include "pipeline/core/view.h"
#include "pipeline/core/virtual_camera.h"

namespace px {

struct FrameRender {
  cv::Mat bgr;       // CV_8UC3, the virtual camera's size: holes filled, effects applied
  cv::Mat depth_m;   // CV_32F, z in the virtual camera; holes filled from the background
  cv::Mat coverage;  // CV_8U, 255 where some source covered the pixel before hole filling
  CoverageReport holes;
  std::vector<ViewId> sources;  // the input views that contributed, most weight first
  // CV_8U, 255 where the frame shows a double image: drawn from a view that a more heavily
  // weighted view contradicts there, or blended from views whose colours disagree beyond noise
  // (ALGORITHM.md section 5). Empty when the back end does not measure it.
  cv::Mat double_image;
};

class SceneRenderer {
 public:
  virtual ~SceneRenderer() = default;

  // "cpu", "gl-osmesa", "gl-egl": for logs, reports and benchmarks.
  virtual std::string_view BackendName() const = 0;

  // The frame the virtual camera sees. Errors name the bad field (VirtualCamera::Validate).
  virtual StatusOr<FrameRender> Render(const VirtualCamera& camera) = 0;

  // Only what Render would leave uncovered before hole filling, as cheaply as the back end can
  // (no colour, depth of field or effects). The camera may be a scaled-down copy of the output
  // camera (CameraModel::Scaled) for speed; the report says the size it was measured at.
  virtual StatusOr<CoverageReport> Coverage(const CameraModel& camera, const Rigid3& cam_from_world) = 0;
};

}  // namespace px
