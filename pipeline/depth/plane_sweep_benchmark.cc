// Speed of the depth stage (segment stereo, depth_stage.h) and of the first plane sweep on the
// Pop9 target configuration: 9 views of 640x480 in a 3x3 lattice (25 mm baseline, f = 560 px),
// depths 0.5-8 m, all 9 depth maps per iteration; and of the segment stereo on a 9x9 light field
// of 512x512 views (the HCI benchmark's shape), centre view only. Peak RSS is printed.
// Run: ./bench/plane_sweep_benchmark.
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <ctime>
#include <opencv2/core.hpp>
#include <vector>

#include "pipeline/core/log.h"
#include "pipeline/depth/depth_stage.h"
#include "pipeline/depth/plane_scene_test_util.h"
#include "pipeline/depth/plane_sweep.h"

namespace px {
namespace {

// A textured wall at 3 m with a textured square at 1 m in front of it. `tilted`: each lens turned
// by about a degree, so warps take the general (non-translation) path.
std::vector<View> TwoPlaneViews(bool tilted) {
  depth::testing::TexturedPlane wall;
  wall.depth_m = 3.0;
  wall.texture = depth::testing::RandomTexture(cv::Size(1400, 1100), 1);
  wall.metres_per_texel = 3.0 / 560.0;
  depth::testing::TexturedPlane square;
  square.depth_m = 1.0;
  square.extent_m = cv::Rect2d(-0.2, -0.15, 0.4, 0.3);
  square.texture = depth::testing::RandomTexture(cv::Size(224, 168), 2);
  square.metres_per_texel = 0.4 / 224;
  std::vector<Rigid3> poses = depth::testing::GridRigPoses(3, 3, 0.025);
  if (tilted) {
    cv::RNG rng(3);
    for (Rigid3& pose : poses) {
      const Eigen::Vector3d axis(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0));
      const Eigen::Quaterniond tilt(Eigen::AngleAxisd(0.015, axis.normalized()));
      pose = Rigid3(tilt, -(tilt * CameraCentre(pose)));
    }
  }
  return depth::testing::RenderViews(poses, CameraModel::Pinhole(640, 480, 560.0), {square, wall});
}

// CPU time of the whole process (all threads), in milliseconds: on a shared machine wall time
// says little, while CPU time / threads is what an idle 2-core target would take.
double ProcessCpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

// Runs `compute` (returning a StatusOr) once per iteration, recording process CPU ms per
// iteration and peak RSS.
template <typename Compute>
void RunIterations(benchmark::State& state, const Compute& compute) {
  double cpu_ms = 0;
  for (auto _ : state) {
    const double start = ProcessCpuMs();
    auto result = compute();
    cpu_ms += ProcessCpuMs() - start;
    if (!result.ok()) state.SkipWithError(result.status().ToString().c_str());
    benchmark::DoNotOptimize(result);
  }
  state.counters["process_cpu_ms"] = cpu_ms / static_cast<double>(state.iterations());
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  state.counters["peak_rss_mib"] = usage.ru_maxrss / 1024.0;  // KiB on Linux
}

void BM_ComputeDepthPop9(benchmark::State& state) {
  (void)SetLogLevels("depth=warn");
  const std::vector<View> views = TwoPlaneViews(state.range(2) != 0);
  PlaneSweepOptions options;
  options.min_depth_m = 0.5;
  options.max_depth_m = 8.0;
  options.num_threads = static_cast<int>(state.range(0));
  options.working_scale = static_cast<double>(state.range(1)) / 100.0;
  RunIterations(state, [&] { return ComputePlaneSweepDepth(views, options); });
  state.SetLabel("9 views 640x480, " + std::to_string(options.num_planes) + " planes, " +
                 std::to_string(options.num_neighbors) + " neighbours");
}
// Args: threads, working scale in percent, tilted lenses (general homographies).
BENCHMARK(BM_ComputeDepthPop9)
    ->Args({1, 50, 0})
    ->Args({2, 50, 0})
    ->Args({2, 50, 1})
    ->Args({2, 100, 0})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2.0);

void BM_LayeredDepthPop9(benchmark::State& state) {
  (void)SetLogLevels("depth=warn");
  const std::vector<View> views = TwoPlaneViews(false);
  DepthOptions options;
  options.min_depth_m = 0.5;
  options.max_depth_m = 8.0;
  options.num_threads = static_cast<int>(state.range(0));
  options.working_scale = static_cast<double>(state.range(1)) / 100.0;
  RunIterations(state, [&] { return ComputeLayeredDepth(views, options); });
  state.SetLabel("segment stereo, 9 views 640x480, layered output");
}
// Args: threads, working scale in percent.
BENCHMARK(BM_LayeredDepthPop9)
    ->Args({2, 50})
    ->Args({2, 100})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2.0);

void BM_LayeredDepthLightField9x9(benchmark::State& state) {
  (void)SetLogLevels("depth=warn");
  // 81 views of 512x512 a few mm apart, as in the HCI light fields (disparities of a few px).
  depth::testing::TexturedPlane wall;
  wall.depth_m = 3.0;
  wall.texture = depth::testing::RandomTexture(cv::Size(1000, 1000), 4);
  wall.metres_per_texel = 3.0 / 500.0;
  depth::testing::TexturedPlane square = wall;
  square.depth_m = 1.5;
  square.extent_m = cv::Rect2d(-0.3, -0.3, 0.6, 0.6);
  square.texture = depth::testing::RandomTexture(cv::Size(400, 400), 5);
  square.metres_per_texel = 0.6 / 400;
  const std::vector<View> views =
      depth::testing::RenderGridRig(9, 9, 0.003, CameraModel::Pinhole(512, 512, 500.0), {square, wall});
  // Arg 1: the options `parallax eval depth` scores HCI with (LightFieldDepthOptions: PatchMatch,
  // 0.2 px planes, 16 spread neighbours); arg 0: the defaults at full resolution, 16 neighbours.
  const bool light_field = state.range(0) != 0;
  DepthOptions options;
  options.working_scale = 1.0;
  options.matching.num_neighbors = 16;
  if (light_field) options = LightFieldDepthOptions(options);
  options.min_depth_m = 1.0;
  options.max_depth_m = 6.0;
  options.num_threads = 2;
  RunIterations(state, [&] { return ComputeLayeredDepthForViews(views, {40}, options); });
  state.SetLabel(std::string("segment stereo, 9x9 views 512x512, centre view, 16 neighbours, ") +
                 (light_field ? "light-field options (as eval depth scores HCI)" : "default options"));
}
// Arg: 1 = LightFieldDepthOptions, 0 = the defaults.
BENCHMARK(BM_LayeredDepthLightField9x9)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);

}  // namespace
}  // namespace px
