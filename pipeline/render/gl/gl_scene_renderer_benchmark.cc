// Frames per second of the render back ends at the preview size (480x320) and clip sizes
// (1200x800; GL also 1920x1080), with 9 (3x3) and 20 (4x5) input views of the analytic two-plane scene cut into
// 16 px segments (~600 per 480x320 view, ~3750 per 1200x800 view), along a dolly across the rig.
// Back ends: gl (OSMesa llvmpipe, or EGL: PX_GL=egl|osmesa picks, default auto), and the CPU
// reference renderer on the same segments.
// Plus a whole 5 s, 30 fps, 1200x800 clip rendered on GL and encoded as H.264. Prints, asserts
// nothing. The CPU column is the whole process's CPU time (llvmpipe's rasteriser threads and
// OpenCV's workers included): on a shared, loaded machine it is the figure to compare, the wall
// time is what a quiet machine would show at best.
#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <opencv2/core.hpp>

#include "pipeline/clip/clip_writer.h"
#include "pipeline/render/cpu_scene_renderer.h"
#include "pipeline/render/gl/gl_scene_renderer.h"
#include "pipeline/render/gl/layered_plane_scene_testing.h"

namespace px::render::gl {
namespace {

constexpr double kBaselineM = 0.025;
constexpr int kTilePx = 16;

CameraModel CameraOfWidth(int width) {
  // The Pop9 tile's field of view (640 px wide, f 560) at any width: 3:2, or 16:9 for a 1080p
  // clip's 1920.
  return CameraModel::Pinhole(width, width == 1920 ? 1080 : width * 2 / 3, 560.0 * width / 640.0);
}
void RigShape(int views, int* rows, int* cols) {
  *rows = views == 20 ? 4 : 3;
  *cols = views == 20 ? 5 : 3;
}
Rigid3 DollyPose(int frame, int frames) {
  const double t = (frame % frames) / (frames - 1.0);
  return Rigid3(Eigen::Quaterniond::Identity(), -Eigen::Vector3d(-0.025 + 0.05 * t, 0.004, 0));
}
GlSceneRendererOptions OptionsFromEnvironment() {
  GlSceneRendererOptions options;
  if (const char* name = std::getenv("PX_GL")) {
    if (auto platform = ParseGlPlatform(name); platform.ok()) options.context.platform = *platform;
  }
  return options;
}

bool WarmUp(GlSceneRenderer& renderer, const CameraModel& camera) {
  VirtualCamera request;
  request.camera = camera;
  request.cam_from_world = DollyPose(0, 150);
  return renderer.Render(request).ok();
}

// The renderer over a rows x cols rig at `camera`, warmed up; null (and the benchmark skipped)
// when it cannot start.
std::unique_ptr<GlSceneRenderer> MakeRenderer(
    const CameraModel& camera, int rows, int cols, benchmark::State& state, bool holes_from_other_views = true) {
  GlSceneRendererOptions options = OptionsFromEnvironment();
  options.holes_from_other_views = holes_from_other_views;
  auto renderer = GlSceneRenderer::Create(
      testing::LayeredPlaneScene(render::testing::PlaneScene{}, rows, cols, kBaselineM, camera, kTilePx), options);
  if (!renderer.ok()) {
    state.SkipWithError(renderer.status().ToString().c_str());
    return nullptr;
  }
  // The first frame compiles llvmpipe's shader variants; it is not what a clip pays per frame.
  if (!WarmUp(**renderer, camera)) {
    state.SkipWithError("warm-up frame failed");
    return nullptr;
  }
  return std::move(renderer).value();
}

// Frame `frame` of the dolly at `camera`; false (and the benchmark skipped) when it fails.
bool RenderDollyFrame(
    GlSceneRenderer& renderer, const CameraModel& camera, int frame, benchmark::State& state, double* hole_ratio) {
  VirtualCamera request;
  request.camera = camera;
  request.cam_from_world = DollyPose(frame, 150);
  auto result = renderer.Render(request);
  if (!result.ok()) {
    state.SkipWithError(result.status().ToString().c_str());
    return false;
  }
  *hole_ratio = result->holes.hole_ratio;
  benchmark::DoNotOptimize(result->bgr.data);
  return true;
}

// range(0): output width (480, 1200 or 1920: 480x320, 1200x800, 1920x1080); range(1): input views (9 or 20).
void BM_GlRenderFrame(benchmark::State& state) {
  const CameraModel camera = CameraOfWidth(static_cast<int>(state.range(0)));
  int rows, cols;
  RigShape(static_cast<int>(state.range(1)), &rows, &cols);
  std::unique_ptr<GlSceneRenderer> renderer = MakeRenderer(camera, rows, cols, state);
  if (!renderer) return;
  state.SetLabel(std::string(renderer->BackendName()) + " " + renderer->context_info().renderer);
  int frame = 0;
  double holes = 0;
  for (auto _ : state) {
    double hole_ratio = 0;
    if (!RenderDollyFrame(*renderer, camera, frame++, state, &hole_ratio)) return;
    holes += hole_ratio;
  }
  state.counters["fps"] = benchmark::Counter(frame, benchmark::Counter::kIsRate);
  state.counters["hole_ratio"] = holes / std::max(frame, 1);
}
BENCHMARK(BM_GlRenderFrame)
    ->ArgsProduct({{480, 1200, 1920}, {9, 20}})
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

// What drawing holes again from other views (hole_views.h) adds to a GL frame with large holes:
// the camera near the centre lens turned 4 degrees to the left, so a strip at the left edge
// (~30 px at 480x320, ~70 px at 1200x800) lies outside the three views blended there.
// range(0): output width; range(1): GlSceneRendererOptions::holes_from_other_views (1 on, 0 off).
// The CPU scene the step needs is made on the warm-up frame, so the figure is a clip's per-frame
// cost; `other_view_pixels` is what the step covered.
void BM_GlHolesFromOtherViews(benchmark::State& state) {
  const CameraModel camera = CameraOfWidth(static_cast<int>(state.range(0)));
  const Eigen::Quaterniond turned(Eigen::AngleAxisd(4.0 * M_PI / 180, Eigen::Vector3d::UnitY()));
  VirtualCamera request;
  request.camera = camera;
  request.cam_from_world = Rigid3(turned, -(turned * Eigen::Vector3d(0.002, 0.004, 0)));
  auto renderer = GlSceneRenderer::Create(
      testing::LayeredPlaneScene(render::testing::PlaneScene{}, 3, 3, kBaselineM, camera, kTilePx), [&] {
        GlSceneRendererOptions options = OptionsFromEnvironment();
        options.holes_from_other_views = state.range(1) != 0;
        return options;
      }());
  // The first frame also makes the step's CPU scene (and compiles llvmpipe's shader variants).
  const std::clock_t first_start = std::clock();
  if (!renderer.ok() || !(*renderer)->Render(request).ok()) {
    state.SkipWithError(renderer.ok() ? "warm-up frame failed" : renderer.status().ToString().c_str());
    return;
  }
  state.counters["first_frame_cpu_ms"] = 1e3 * static_cast<double>(std::clock() - first_start) / CLOCKS_PER_SEC;
  double holes = 0, covered = 0;
  int frames = 0;
  for (auto _ : state) {
    auto frame = (*renderer)->Render(request);
    if (!frame.ok()) {
      state.SkipWithError(frame.status().ToString().c_str());
      return;
    }
    benchmark::DoNotOptimize(frame->bgr.data);
    holes += frame->holes.hole_ratio;
    covered += (*renderer)->last_frame().other_view_pixels;
    ++frames;
  }
  state.counters["hole_ratio"] = holes / std::max(frames, 1);
  state.counters["other_view_pixels"] = covered / std::max(frames, 1);
}
BENCHMARK(BM_GlHolesFromOtherViews)
    ->ArgsProduct({{480, 1200}, {1, 0}})
    ->ArgNames({"width", "other_views"})
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

// Where a GL frame's time goes: the process CPU ms of each pass (GlFrameStats; a glFinish after
// each GL pass), the draws and the segment rectangles, averaged over the frames. floor:1 draws
// the segment rectangles with a shader that discards at once: the rasteriser's own cost, the
// least any shader can take on this GL (the frame is then all holes, so post_ms is not the
// real frame's).
void BM_GlFramePasses(benchmark::State& state) {
  const CameraModel camera = CameraOfWidth(static_cast<int>(state.range(0)));
  int rows, cols;
  RigShape(static_cast<int>(state.range(1)), &rows, &cols);
  std::unique_ptr<GlSceneRenderer> renderer = MakeRenderer(camera, rows, cols, state);
  if (!renderer) return;
  renderer->set_time_passes(true);
  renderer->set_segment_floor(state.range(2) != 0);
  int frame = 0;
  GlFrameStats sum;
  for (auto _ : state) {
    double hole_ratio = 0;
    if (!RenderDollyFrame(*renderer, camera, frame++, state, &hole_ratio)) return;
    const GlFrameStats& s = renderer->last_frame();
    sum.draws += s.draws, sum.instances += s.instances;
    sum.weights_ms += s.weights_ms, sum.setup_ms += s.setup_ms, sum.segments_ms += s.segments_ms;
    sum.resolve_ms += s.resolve_ms, sum.readback_ms += s.readback_ms, sum.post_ms += s.post_ms;
  }
  const double n = std::max(frame, 1);
  state.counters["draws"] = sum.draws / n;
  state.counters["instances"] = sum.instances / n;
  state.counters["weights_ms"] = sum.weights_ms / n;
  state.counters["setup_ms"] = sum.setup_ms / n;
  state.counters["segments_ms"] = sum.segments_ms / n;
  state.counters["resolve_ms"] = sum.resolve_ms / n;
  state.counters["readback_ms"] = sum.readback_ms / n;
  state.counters["post_ms"] = sum.post_ms / n;
}
BENCHMARK(BM_GlFramePasses)
    ->ArgsProduct({{480, 1200}, {9}, {0, 1}})
    ->ArgNames({"width", "views", "floor"})
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

// The direction stage's question: coverage and H(V) at 1/8 of 1200x800.
void BM_GlCoverage(benchmark::State& state) {
  const CameraModel camera = CameraOfWidth(1200);
  std::unique_ptr<GlSceneRenderer> renderer = MakeRenderer(camera, 3, 3, state);
  if (!renderer) return;
  const CameraModel small = camera.Scaled(0.125);
  int frame = 0;
  for (auto _ : state) {
    auto report = renderer->Coverage(small, DollyPose(frame++, 150));
    if (!report.ok()) {
      state.SkipWithError(report.status().ToString().c_str());
      return;
    }
    benchmark::DoNotOptimize(report->hole_score);
  }
  state.counters["calls_per_s"] = benchmark::Counter(frame, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_GlCoverage)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();

// The CPU reference renderer (CpuSceneRenderer, all cores) on the same segments, sizes and path.
void BM_CpuSceneFrame(benchmark::State& state) {
  const CameraModel camera = CameraOfWidth(static_cast<int>(state.range(0)));
  int rows, cols;
  RigShape(static_cast<int>(state.range(1)), &rows, &cols);
  std::vector<View> views;
  std::vector<DepthMap> depths;
  render::testing::MakeLatticeViews(render::testing::PlaneScene{}, rows, cols, kBaselineM, camera, &views, &depths);
  std::vector<LayeredDepthView> layers;
  for (PosedLayeredView& posed :
       testing::LayeredPlaneScene(render::testing::PlaneScene{}, rows, cols, kBaselineM, camera, kTilePx)) {
    layers.push_back(std::move(posed.depth));
  }
  auto renderer = CpuSceneRenderer::Create(views, layers, RenderOptions{});
  if (!renderer.ok()) {
    state.SkipWithError(renderer.status().ToString().c_str());
    return;
  }
  state.SetLabel("cpu reference, " + std::to_string(cv::getNumThreads()) + " threads");
  VirtualCamera request;
  request.camera = camera;
  int frame = 0;
  for (auto _ : state) {
    request.cam_from_world = DollyPose(frame++, 150);
    auto result = (*renderer)->Render(request);
    if (!result.ok()) {
      state.SkipWithError(result.status().ToString().c_str());
      return;
    }
    benchmark::DoNotOptimize(result->bgr.data);
  }
  state.counters["fps"] = benchmark::Counter(frame, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_CpuSceneFrame)
    ->ArgsProduct({{480, 1200}, {9, 20}})
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

// The clip goal: 150 frames of 1200x800 rendered on GL and encoded (H.264, veryfast,
// CRF 20) in under 8 s. One iteration is one whole clip.
void BM_GlClipRenderAndEncode(benchmark::State& state) {
  const CameraModel camera = CameraOfWidth(1200);
  std::unique_ptr<GlSceneRenderer> renderer = MakeRenderer(camera, 3, 3, state);
  if (!renderer) return;
  const std::filesystem::path path = std::filesystem::temp_directory_path() / "px_gl_clip_benchmark.mp4";
  double render_s = 0, encode_s = 0;
  for (auto _ : state) {
    auto writer = clip::OpenClipWriter(path, camera.width, camera.height, clip::ClipOptions{});
    if (!writer.ok()) {
      state.SkipWithError(writer.status().ToString().c_str());
      return;
    }
    for (int frame = 0; frame < 150; ++frame) {
      VirtualCamera request;
      request.camera = camera;
      request.cam_from_world = DollyPose(frame, 150);
      const auto t0 = std::chrono::steady_clock::now();
      auto result = renderer->Render(request);
      const auto t1 = std::chrono::steady_clock::now();
      if (!result.ok() || !(*writer)->Write(result->bgr).ok()) {
        state.SkipWithError("render or encode failed");
        return;
      }
      render_s += std::chrono::duration<double>(t1 - t0).count();
      encode_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
    }
    if (!(*writer)->Finish().ok()) state.SkipWithError("finishing the clip failed");
  }
  state.counters["render_s"] = render_s / state.iterations();
  state.counters["encode_s"] = encode_s / state.iterations();
  std::error_code ec;
  std::filesystem::remove(path, ec);
}
BENCHMARK(BM_GlClipRenderAndEncode)->Iterations(1)->Unit(benchmark::kSecond)->MeasureProcessCPUTime()->UseRealTime();

}  // namespace
}  // namespace px::render::gl
