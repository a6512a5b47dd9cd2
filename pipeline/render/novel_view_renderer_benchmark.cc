// Time per rendered frame at the Pop9 tile size (640x480), along an establishing dolly across a
// 3x3 rig of the analytic two-plane scene. Prints figures, asserts nothing.
#include <benchmark/benchmark.h>

#include <opencv2/core.hpp>
#include <cstdlib>

#include "pipeline/core/log.h"
#include "pipeline/render/novel_view_renderer.h"
#include "pipeline/render/plane_scene_testing.h"

namespace px {
namespace {

// range(0): OpenCV threads; range(1): 0 = the dolly across the rig (-25 .. +25 mm, few holes),
// 1 = the same dolly 10 cm to the left of the rig (large disocclusions to fill).
void BM_RenderDollyFrame(benchmark::State& state) {
  cv::setNumThreads(static_cast<int>(state.range(0)));
  const double offset_m = state.range(1) == 0 ? 0.0 : -0.10;
  // PX_LOG=render=debug prints each frame's pass timings.
  if (const char* levels = std::getenv("PX_LOG")) (void)SetLogLevels(levels);
  const CameraModel camera = CameraModel::Pinhole(640, 480, 560);
  render::testing::PlaneScene scene;
  std::vector<View> views;
  std::vector<DepthMap> depths;
  render::testing::MakeLatticeViews(scene, 3, 3, 0.025, camera, &views, &depths);
  auto renderer = NovelViewRenderer::Create(views, depths, RenderOptions{});
  if (!renderer.ok()) {
    state.SkipWithError(renderer.status().ToString().c_str());
    return;
  }
  int frame = 0;
  double holes = 0;
  for (auto _ : state) {
    // 150 frames from x = -25 mm to +25 mm, cycling.
    const double t = (frame++ % 150) / 149.0;
    const Rigid3 pose(Eigen::Quaterniond::Identity(), -Eigen::Vector3d(offset_m - 0.025 + 0.05 * t, 0, 0));
    auto result = (*renderer)->Render(camera, pose);
    if (!result.ok()) {
      state.SkipWithError(result.status().ToString().c_str());
      return;
    }
    holes += result->hole_ratio;
    benchmark::DoNotOptimize(result->bgr.data);
  }
  state.counters["hole_ratio"] = holes / std::max(frame, 1);
}
BENCHMARK(BM_RenderDollyFrame)
    ->Args({1, 0})
    ->Args({2, 0})
    ->Args({1, 1})
    ->Args({2, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace px
