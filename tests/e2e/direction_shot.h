// A simulated Pop9 shot set up for the direction stage alone: views, the simulator's true depth
// (full confidence) and a CPU renderer over that depth as layered segments for Coverage(). Shared
// by direction_test and direction_benchmark.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "pipeline/core/view.h"
#include "pipeline/direct/plan_camera_path.h"
#include "pipeline/render/cpu_scene_renderer.h"

namespace px::e2e {

struct DirectionShot {
  std::vector<View> views;
  std::vector<DepthMap> depths;
  std::unique_ptr<CpuSceneRenderer> renderer;

  // The renderer's Coverage as the direction stage takes it.
  CoverageFunction Coverage();
};

// `scene`: a sim/scenes name; `tile_scale`: 1 = the product's 640x480 views (e2e::Pop9Spec).
StatusOr<std::unique_ptr<DirectionShot>> MakeDirectionShot(const std::string& scene, double tile_scale);

}  // namespace px::e2e
