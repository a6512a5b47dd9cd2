// End to end: a whole 5 s, 30 fps clip (150 frames) rendered by the CPU back end and encoded as
// H.264 (x264 veryfast, the clip writer's default), at 1200x800 from 9 (3x3, 25 mm) and 20 (5x4,
// 12.5 mm) views of the analytic two-plane scene with exact layered depth, along the same dolly as
// render_benchmark (2 cm in front of the rig). As in the product (pipeline/run), the encoder works
// on its own thread (OverlappedFrameSink) while the next frame renders. The goal: under
// 8 s on 2 cores. Prints the clip's seconds, the process CPU seconds (every thread: on a shared
// machine the figure to compare), and the time the render loop spent rendering and waiting for
// the encoder; asserts nothing.
#include <benchmark/benchmark.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <string>

#include <sys/resource.h>
#include <unistd.h>

#include "pipeline/clip/clip_writer.h"
#include "pipeline/core/stage_clock.h"
#include "pipeline/render/cpu_scene_renderer.h"
#include "pipeline/render/render_test_util.h"
#include "pipeline/run/overlapped_frame_sink.h"

namespace px {
namespace {

double SecondsSince(Clock::time_point start) { return MsSince(start) / 1000; }

// User + system CPU seconds of the whole process (all threads) so far.
double ProcessCpuSeconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_utime.tv_sec + usage.ru_stime.tv_sec + 1e-6 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

// Frames into the clip writer (called on the overlapped sink's thread).
class WriterSink final : public FrameSink {
 public:
  explicit WriterSink(clip::ClipWriter* writer) : writer_(writer) {}
  Status Consume(int /*index*/, const cv::Mat& bgr) override { return writer_->Write(bgr); }

 private:
  clip::ClipWriter* writer_;
};

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
  double render_s = 0, wait_s = 0, encode_s = 0, clip_s = 0, cpu_s = 0;
  int clips = 0;
  for (auto _ : state) {
    const Clock::time_point clip_start = Clock::now();
    const double cpu_start = ProcessCpuSeconds();
    auto writer = clip::OpenClipWriter(path, shot.camera.width, shot.camera.height, clip::ClipOptions{});
    if (!writer.ok()) {
      state.SkipWithError(writer.status().ToString().c_str());
      return;
    }
    WriterSink sink(writer->get());
    OverlappedFrameSink overlapped(&sink, 2);
    for (int frame = 0; frame < kFrames; ++frame) {
      const double t = frame / (kFrames - 1.0);
      VirtualCamera camera;
      camera.camera = shot.camera;
      camera.cam_from_world =
          Rigid3(Eigen::Quaterniond::Identity(), -Eigen::Vector3d(-0.025 + 0.05 * t, 0.004, 0.02));
      const Clock::time_point start = Clock::now();
      auto result = (*renderer)->Render(camera);
      render_s += SecondsSince(start);
      if (!result.ok()) {
        state.SkipWithError(result.status().ToString().c_str());
        return;
      }
      const Status queued = overlapped.Consume(frame, result->bgr);
      if (!queued.ok()) {
        state.SkipWithError(queued.ToString().c_str());
        return;
      }
    }
    Status finished = overlapped.Finish();
    if (finished.ok()) finished = (*writer)->Finish();
    if (!finished.ok()) {
      state.SkipWithError(finished.ToString().c_str());
      return;
    }
    wait_s += overlapped.wait_ms() / 1000;
    encode_s += overlapped.sink_ms() / 1000;
    clip_s += SecondsSince(clip_start);
    cpu_s += ProcessCpuSeconds() - cpu_start;
    ++clips;
  }
  std::error_code ignored;
  std::filesystem::remove(path, ignored);
  const double n = std::max(clips, 1);
  state.counters["clip_s"] = clip_s / n;
  state.counters["cpu_s"] = cpu_s / n;
  state.counters["render_ms_per_frame"] = 1000 * render_s / n / kFrames;
  state.counters["wait_ms_per_frame"] = 1000 * wait_s / n / kFrames;
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
