// Frames per second of the CPU back end (ALGORITHM.md) along a dolly across the rig, for the
// analytic two-plane scene with exact layered depth: 480x320 and 1200x800 output from views of the
// same size, 9 views (3x3, 25 mm) and 20 views (5x4, 12.5 mm), preview and offline quality; and
// Coverage() at 1/8 of 1200x800 (the direction stage's viewpoint search); the viewing weights'
// flattening over a 1200x800 frame. Prints, asserts nothing.
// The CPU column of BM_RenderFrame is the process's (every thread's) CPU time per frame: on a
// shared machine the figure to compare. PX_LOG=render=debug prints each frame's pass timings.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <memory>
#include <tuple>
#include <vector>

#include "pipeline/core/log.h"
#include "pipeline/render/cpu_scene_renderer.h"
#include "pipeline/render/render_test_util.h"
#include "pipeline/render/view_mesh.h"

namespace px {
namespace {

using render::testing::CachedLatticeShot;
using render::testing::LatticeShot;

// range(0): output width (480 or 1200), range(1): views (9 or 20), range(2): 0 preview, 1 offline.
void BM_RenderFrame(benchmark::State& state) {
  if (const char* levels = std::getenv("PX_LOG")) (void)SetLogLevels(levels);
  const LatticeShot& shot = CachedLatticeShot(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  RenderOptions options;
  options.quality = state.range(2) == 0 ? RenderQuality::kPreview : RenderQuality::kOffline;
  auto renderer = CpuSceneRenderer::Create(shot.views, shot.layers, options);
  if (!renderer.ok()) {
    state.SkipWithError(renderer.status().ToString().c_str());
    return;
  }
  int frame = 0;
  double holes = 0, composite_ms = 0, fragments = 0, segments = 0;
  for (auto _ : state) {
    // 150 frames from x = -25 mm to +25 mm, 2 cm in front of the rig, cycling.
    const double t = (frame++ % 150) / 149.0;
    VirtualCamera camera;
    camera.camera = shot.camera;
    camera.cam_from_world = Rigid3(Eigen::Quaterniond::Identity(), -Eigen::Vector3d(-0.025 + 0.05 * t, 0.004, 0.02));
    auto result = (*renderer)->Render(camera);
    if (!result.ok()) {
      state.SkipWithError(result.status().ToString().c_str());
      return;
    }
    holes += result->holes.hole_ratio;
    composite_ms += (*renderer)->last_frame().composite_ms;
    fragments += static_cast<double>((*renderer)->last_frame().fragments);
    segments += (*renderer)->last_frame().segments_drawn;
    benchmark::DoNotOptimize(result->bgr.data);
  }
  state.counters["fps"] = benchmark::Counter(static_cast<double>(frame), benchmark::Counter::kIsRate);
  state.counters["hole_ratio"] = holes / std::max(frame, 1);
  state.counters["composite_ms"] = composite_ms / std::max(frame, 1);
  state.counters["fragments_per_pixel"] =
      fragments / std::max(frame, 1) / static_cast<double>(shot.camera.width * shot.camera.height);
  state.counters["segments"] = segments / std::max(frame, 1);
}
BENCHMARK(BM_RenderFrame)
    ->ArgNames({"width", "views", "offline"})
    ->Args({480, 9, 0})
    ->Args({480, 20, 0})
    ->Args({1200, 9, 0})
    ->Args({1200, 20, 0})
    ->Args({480, 9, 1})
    ->Args({480, 20, 1})
    ->Args({1200, 9, 1})
    ->Args({1200, 20, 1})
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

// Coverage() at 1/8 of the 1200x800 output (150x100), as the direction stage calls it.
void BM_Coverage(benchmark::State& state) {
  if (const char* levels = std::getenv("PX_LOG")) (void)SetLogLevels(levels);
  const LatticeShot& shot = CachedLatticeShot(1200, static_cast<int>(state.range(0)));
  auto renderer = CpuSceneRenderer::Create(shot.views, shot.layers, RenderOptions{});
  if (!renderer.ok()) {
    state.SkipWithError(renderer.status().ToString().c_str());
    return;
  }
  const CameraModel small = shot.camera.Scaled(1.0 / 8);
  int call = 0;
  double score = 0;
  for (auto _ : state) {
    const double t = (call++ % 64) / 63.0;
    auto report = (*renderer)->Coverage(
        small, Rigid3(Eigen::Quaterniond::Identity(), -Eigen::Vector3d(-0.05 + 0.1 * t, 0.01, 0.05 * t)));
    if (!report.ok()) {
      state.SkipWithError(report.status().ToString().c_str());
      return;
    }
    score += report->hole_score;
  }
  state.counters["hole_score"] = score / std::max(call, 1);
}
BENCHMARK(BM_Coverage)->ArgNames({"views"})->Arg(9)->Arg(20)->Unit(benchmark::kMicrosecond)->UseRealTime();

// The viewing weights' flattening (FlattenViewingWeights) over a 1200x800 frame's slots, per
// frame: range(0) is the exponent in hundredths (50: the default square root, 70: pow).
void BM_FlattenViewingWeights(benchmark::State& state) {
  std::vector<render::ViewSlots> slots(1200 * 800);
  for (size_t i = 0; i < slots.size(); ++i) {
    const float a = static_cast<float>(i % 97) / 97.0f, b = (1.0f - a) * static_cast<float>(i % 13) / 13.0f;
    slots[i].view = {0, 1, 2};
    slots[i].weight = {a, b, 1.0f - a - b};
  }
  const std::vector<render::ViewSlots> barycentric = slots;
  const double exponent = static_cast<double>(state.range(0)) / 100.0;
  for (auto _ : state) {
    state.PauseTiming();
    slots = barycentric;
    state.ResumeTiming();
    render::FlattenViewingWeights(exponent, &slots);
    benchmark::DoNotOptimize(slots.data());
  }
}
BENCHMARK(BM_FlattenViewingWeights)->ArgNames({"exponent_x100"})->Arg(50)->Arg(70)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace px
