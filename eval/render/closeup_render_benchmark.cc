// The product's close-ups, per frame: the simulated one_face scene on the Pop9 (9 views of
// 640x480) with the depth stage's layered depth, rendered by the CPU back end (preview) along the
// dolly in `parallax clip` plans for it (closeup_eval.h), halfway and at its close-up end, with
// the seam skirts (pipeline/render/seam_skirts.h) on and off. OpenCV
// runs one thread here, so the CPU column is the frame's whole CPU time and is comparable under
// load; create_ms is the scene's set-up (once per shot, wall time). Asserts nothing.
#include <benchmark/benchmark.h>

#include <chrono>
#include <memory>
#include <opencv2/core/utility.hpp>
#include <optional>

#include "eval/render/closeup_eval.h"
#include "eval/render/render_eval_steps.h"
#include "pipeline/depth/depth_stage.h"
#include "pipeline/render/cpu_scene_renderer.h"
#include "sim/synthetic/data_paths.h"

namespace px::eval {
namespace {

struct CloseUpShot {
  SimLattice lattice;
  std::vector<LayeredDepthView> layers;
  CameraPath path;
};

// Made once (ray casting and the depth stage take seconds); nullopt when it cannot be made.
const std::optional<CloseUpShot>& Shot() {
  static const std::optional<CloseUpShot> shot = []() -> std::optional<CloseUpShot> {
    RenderEvalOptions options;
    StatusOr<SimLattice> lattice = RenderSimLattice(sim::ScenesDir() / "one_face.json", SimCameraSpec::Pop9(), options);
    if (!lattice.ok()) return std::nullopt;
    const DepthOptions depth =
        options.depth_stage.WithDefaultDepthRange(lattice->spec.depth_min_m, lattice->spec.depth_max_m);
    StatusOr<DepthStageResult> layered = ComputeLayeredDepth(lattice->views, depth);
    StatusOr<CameraPath> path = RecordedDollyIn("one_face", lattice->views.front().camera, 1.0);
    if (!layered.ok() || !path.ok()) return std::nullopt;
    return CloseUpShot{std::move(lattice).value(), std::move(layered->layered), std::move(path).value()};
  }();
  return shot;
}

// range(0): 1 = seam skirts on (the default), 0 = off; range(1): path time in per cent.
void BM_CloseUpFrame(benchmark::State& state) {
  cv::setNumThreads(1);
  const std::optional<CloseUpShot>& shot = Shot();
  if (!shot) {
    state.SkipWithError("cannot make the one_face shot (scene, depth stage or path)");
    return;
  }
  RenderOptions options;
  if (state.range(0) == 0) {
    options.seam_skirts.max_step = 0;
  }
  const auto start = std::chrono::steady_clock::now();
  auto renderer = CpuSceneRenderer::Create(shot->lattice.views, shot->layers, options);
  state.counters["create_ms"] =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  if (!renderer.ok()) {
    state.SkipWithError(renderer.status().ToString().c_str());
    return;
  }
  const VirtualCamera camera = shot->path.FrameAt(state.range(1) / 100.0);
  long fragments = 0;
  for (auto _ : state) {
    auto frame = (*renderer)->Render(camera);
    if (!frame.ok()) {
      state.SkipWithError(frame.status().ToString().c_str());
      return;
    }
    fragments += (*renderer)->last_frame().fragments;
  }
  state.counters["fragments_per_pixel"] = static_cast<double>(fragments) / (static_cast<double>(state.iterations()) *
                                                                            camera.camera.width * camera.camera.height);
  state.counters["segments"] = (*renderer)->last_frame().segments_drawn;
  cv::setNumThreads(-1);
}

BENCHMARK(BM_CloseUpFrame)
    ->ArgNames({"seams", "t_percent"})
    ->Args({0, 50})
    ->Args({1, 50})
    ->Args({0, 100})
    ->Args({1, 100})
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace px::eval
