// Render time of a full simulated frame (the ray caster is most of a synthetic capture).
// Run with --benchmark_filter and e.g. --threads via PX_BENCH_THREADS (default 2, the target).
#include <benchmark/benchmark.h>

#include <cstdlib>

#include "sim/synthetic/data_paths.h"
#include "sim/synthetic/scene_json.h"
#include "sim/synthetic/sim_sensor.h"

namespace px::sim {
namespace {

void RenderPreset(benchmark::State& state, const SimCameraSpec& spec, const char* scene_name) {
  const char* threads = std::getenv("PX_BENCH_THREADS");
  cv::setNumThreads(threads != nullptr ? std::atoi(threads) : 2);
  auto scene = LoadScene(ScenesDir() / (std::string(scene_name) + ".json"));
  if (!scene.ok()) {
    state.SkipWithError(scene.status().ToString().c_str());
    return;
  }
  for (auto _ : state) {
    auto frame = RenderSensorFrame(*scene, spec, 1);
    benchmark::DoNotOptimize(frame);
  }
  state.counters["threads"] = cv::getNumThreads();
  state.counters["views"] = spec.rows * spec.cols;
}

void BM_Pop9StillLife(benchmark::State& state) { RenderPreset(state, SimCameraSpec::Pop9(), "still_life"); }
void BM_Pop9OneFace(benchmark::State& state) { RenderPreset(state, SimCameraSpec::Pop9(), "one_face"); }
void BM_Pop9StillLifeDistorted(benchmark::State& state) {
  SimCameraSpec spec = SimCameraSpec::Pop9();
  spec.distortion = {-0.12, 0.03, 0.0008, -0.0005, 0};
  RenderPreset(state, spec, "still_life");
}
void BM_Integral5x4StillLife(benchmark::State& state) {
  RenderPreset(state, SimCameraSpec::Integral5x4(), "still_life");
}

BENCHMARK(BM_Pop9StillLife)->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime()->MinTime(3);
BENCHMARK(BM_Pop9OneFace)->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime()->MinTime(3);
BENCHMARK(BM_Pop9StillLifeDistorted)->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime()->MinTime(3);
BENCHMARK(BM_Integral5x4StillLife)->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime()->MinTime(3);

}  // namespace
}  // namespace px::sim
