#include "tests/e2e/direction_shot.h"

#include "pipeline/render/layered_from_depth.h"
#include "pipeline/run/pipeline.h"
#include "tests/e2e/e2e_shot.h"

namespace px::e2e {

CoverageFunction DirectionShot::Coverage() {
  return [this](const CameraModel& camera, const Rigid3& cam_from_world) {
    return renderer->Coverage(camera, cam_from_world);
  };
}

StatusOr<std::unique_ptr<DirectionShot>> MakeDirectionShot(const std::string& scene, double tile_scale) {
  PX_ASSIGN_OR_RETURN(SimulatedShot captured, CaptureShot(Pop9Spec(tile_scale), scene));
  auto shot = std::make_unique<DirectionShot>();
  std::vector<std::string> warnings;
  PX_ASSIGN_OR_RETURN(shot->views, MakeViewsFromCapture(captured.capture, captured.rig, &warnings));
  for (const auto& truth : captured.truth.views) {
    DepthMap depth;
    depth.id = truth.id;
    depth.depth_m = truth.depth_m;
    depth.confidence = cv::Mat(truth.depth_m.size(), CV_32F, cv::Scalar(1));
    shot->depths.push_back(std::move(depth));
  }
  // The true depth as layered segments, so that what is measured is direction alone.
  std::vector<LayeredDepthView> layers;
  for (size_t i = 0; i < shot->views.size(); ++i) {
    PX_ASSIGN_OR_RETURN(LayeredDepthView layered, LayeredDepthFromDepthMap(shot->views[i], shot->depths[i]));
    layers.push_back(std::move(layered));
  }
  PX_ASSIGN_OR_RETURN(shot->renderer, CpuSceneRenderer::Create(shot->views, layers, RenderOptions{}));
  return shot;
}

}  // namespace px::e2e
