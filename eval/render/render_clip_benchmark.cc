// End to end: a whole 5 s, 30 fps clip (150 frames) rendered by the CPU back end and encoded as
// H.264 (x264 veryfast, the clip writer's default), at 1200x800 from 9 (3x3, 25 mm) and 20 (5x4,
// 12.5 mm) views of the analytic two-plane scene with exact layered depth, along the same dolly as
// render_benchmark (2 cm in front of the rig). The goal: under 8 s on 2 cores. Prints the
// clip's seconds and the split between rendering and encoding; asserts nothing.
#include <benchmark/benchmark.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <string>

#include <unistd.h>

#include "pipeline/clip/clip_writer.h"
#include "pipeline/render/cpu_scene_renderer.h"
#include "pipeline/render/render_test_util.h"

namespace px {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

using render::testing::CachedLatticeShot;
using render::testing::LatticeShot;

// range(0): output width (1200), range(1): views (9 or 20). One iteration = one whole clip.
void BM_RenderAndEncodeClip(benchmark::State& state) {
  constexpr int kFrames = 150;
  const LatticeShot& shot = CachedLatticeShot(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  auto renderer = CpuSceneRenderer::Create(shot.views, shot.layers, RenderOptions{});
  if (!renderer.ok()) {
    state.SkipWithError(renderer.status().ToString().c_str());
    return;
  }
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("px_render_clip_benchmark_" + std::to_string(getpid()) + ".mp4");
  double render_s = 0, encode_s = 0, clip_s = 0;
  int clips = 0;
  for (auto _ : state) {
    const Clock::time_point clip_start = Clock::now();
    auto writer = clip::OpenClipWriter(path, shot.camera.width, shot.camera.height, clip::ClipOptions{});
    if (!writer.ok()) {
      state.SkipWithError(writer.status().ToString().c_str());
      return;
    }
    for (int frame = 0; frame < kFrames; ++frame) {
      const double t = frame / (kFrames - 1.0);
      VirtualCamera camera;
      camera.camera = shot.camera;
      camera.cam_from_world =
          Rigid3(Eigen::Quaterniond::Identity(), -Eigen::Vector3d(-0.025 + 0.05 * t, 0.004, 0.02));
      Clock::time_point start = Clock::now();
      auto result = (*renderer)->Render(camera);
      render_s += SecondsSince(start);
      if (!result.ok()) {
        state.SkipWithError(result.status().ToString().c_str());
        return;
      }
      start = Clock::now();
      const Status written = (*writer)->Write(result->bgr);
      encode_s += SecondsSince(start);
      if (!written.ok()) {
        state.SkipWithError(written.ToString().c_str());
        return;
      }
    }
    const Clock::time_point start = Clock::now();
    const Status finished = (*writer)->Finish();
    encode_s += SecondsSince(start);
    if (!finished.ok()) {
      state.SkipWithError(finished.ToString().c_str());
      return;
    }
    clip_s += SecondsSince(clip_start);
    ++clips;
  }
  std::error_code ignored;
  std::filesystem::remove(path, ignored);
  const double n = std::max(clips, 1);
  state.counters["clip_s"] = clip_s / n;
  state.counters["render_ms_per_frame"] = 1000 * render_s / n / kFrames;
  state.counters["encode_ms_per_frame"] = 1000 * encode_s / n / kFrames;
  state.counters["fps"] = kFrames * n / std::max(clip_s, 1e-9);
}
BENCHMARK(BM_RenderAndEncodeClip)
    ->ArgNames({"width", "views"})
    ->Args({1200, 9})
    ->Args({1200, 20})
    ->Iterations(1)
    ->Unit(benchmark::kSecond)
    ->UseRealTime();

}  // namespace
}  // namespace px
