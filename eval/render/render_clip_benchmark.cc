// End to end: a whole 5 s, 30 fps clip (150 frames) rendered by the CPU back end and encoded as
// H.264 (x264 veryfast, the clip writer's default), at 1200x800 from 9 (3x3, 25 mm) and 20 (5x4,
// 12.5 mm) views of the analytic two-plane scene with exact layered depth, along the same dolly as
// render_benchmark (2 cm in front of the rig). As in the product (pipeline/run), the encoder works
// on its own thread (OverlappedFrameSink) while the next frame renders. The goal: under
// 8 s on 2 cores. Prints the clip's seconds, the process CPU seconds (every thread: on a shared
// machine the figure to compare), and the time the render loop spent rendering and waiting for
// the encoder; asserts nothing. For encoder comparisons (the preset is a product decision; the
// default stays the product's): PX_CLIP_PRESET=<x264 preset> encodes with another preset,
// PX_CLIP_FORMAT=<mp4|png|...> writes another format, PX_CLIP_KEEP=<path> keeps the clip there
// (without it the clip goes to a temporary file, then away); clip_mb is its size.
#include <benchmark/benchmark.h>
#include <sys/resource.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>

#include "pipeline/clip/clip_writer.h"
#include "pipeline/core/stage_clock.h"
#include "pipeline/render/cpu_scene_renderer.h"
#include "pipeline/render/render_test_util.h"
#include "pipeline/run/overlapped_frame_sink.h"

namespace px {
namespace {

double SecondsSince(StageClock::time_point start) { return MsSince(start) / 1000; }

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

// The clip options and path from PX_CLIP_PRESET, PX_CLIP_FORMAT and PX_CLIP_KEEP (see above).
StatusOr<clip::ClipOptions> ClipOptionsFromEnvironment() {
  clip::ClipOptions options;
  if (const char* preset = std::getenv("PX_CLIP_PRESET")) options.preset = preset;
  if (const char* format = std::getenv("PX_CLIP_FORMAT")) {
    PX_ASSIGN_OR_RETURN(options.format, clip::ParseClipFormat(format));
  }
  return options;
}
std::filesystem::path ClipPathFromEnvironment(const clip::ClipOptions& options) {
  if (const char* keep = std::getenv("PX_CLIP_KEEP")) return keep;
  return std::filesystem::temp_directory_path() / ("px_render_clip_benchmark_" + std::to_string(getpid()) +
                                                   std::string(clip::ClipFormatExtension(options.format)));
}

// Bytes under `path` (a file, or a folder of frames).
double SizeOnDisk(const std::filesystem::path& path) {
  std::error_code error;
  if (!std::filesystem::is_directory(path, error)) return static_cast<double>(std::filesystem::file_size(path, error));
  double bytes = 0;
  for (const auto& entry : std::filesystem::directory_iterator(path, error)) bytes += entry.file_size(error);
  return bytes;
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
  const StatusOr<clip::ClipOptions> clip_options = ClipOptionsFromEnvironment();
  if (!clip_options.ok()) {
    state.SkipWithError(clip_options.status().ToString().c_str());
    return;
  }
  const std::filesystem::path path = ClipPathFromEnvironment(*clip_options);
  double render_s = 0, wait_s = 0, encode_s = 0, clip_s = 0, cpu_s = 0;
  int clips = 0;
  for (auto _ : state) {
    const StageClock::time_point clip_start = StageClock::now();
    const double cpu_start = ProcessCpuSeconds();
    auto writer = clip::OpenClipWriter(path, shot.camera.width, shot.camera.height, *clip_options);
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
      camera.cam_from_world = Rigid3(Eigen::Quaterniond::Identity(), -Eigen::Vector3d(-0.025 + 0.05 * t, 0.004, 0.02));
      const StageClock::time_point start = StageClock::now();
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
  const double clip_bytes = SizeOnDisk(path);
  if (std::getenv("PX_CLIP_KEEP") == nullptr) {
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
  const double n = std::max(clips, 1);
  state.counters["clip_s"] = clip_s / n;
  state.counters["clip_mb"] = clip_bytes / 1e6;
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
