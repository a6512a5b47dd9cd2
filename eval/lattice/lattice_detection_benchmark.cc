// Lattice detection time on full-size simulated frames with varied tiles (Pop9 3x3: 2016x1536;
// integral 5x4: 1744x1080), blind and near a prior, and on the real ActionSampler scan when ../shared/data is
// there. The frame is rendered once, outside the timing. PX_BENCH_THREADS sets OpenCV's threads
// (default 2, the target).
#include <benchmark/benchmark.h>

#include <cstdlib>

#include "eval/lattice/lattice_eval.h"
#include "sim/synthetic/data_paths.h"
#include "sim/synthetic/scene_json.h"

namespace px::eval {
namespace {

void SetThreads() {
  const char* threads = std::getenv("PX_BENCH_THREADS");
  cv::setNumThreads(threads != nullptr ? std::atoi(threads) : 2);
}

void Detect(benchmark::State& state, const cv::Mat& frame, const LatticeLayout* prior) {
  for (auto _ : state) {
    StatusOr<LatticeDetection> detection = DetectLattice(frame, LatticeOptions(), prior);
    if (!detection.ok()) {
      state.SkipWithError(detection.status().ToString().c_str());
      return;
    }
    benchmark::DoNotOptimize(detection);
  }
  state.counters["threads"] = cv::getNumThreads();
  state.counters["megapixels"] = frame.total() / 1e6;
}

void DetectSim(benchmark::State& state, const std::string& case_name, bool with_prior) {
  SetThreads();
  StatusOr<sim::Scene> scene = sim::LoadScene(sim::ScenesDir() / "still_life.json");
  if (!scene.ok()) {
    state.SkipWithError(scene.status().ToString().c_str());
    return;
  }
  for (const SimLatticeCase& c : StandardSimLatticeCases(1.0)) {
    if (c.name != case_name) continue;
    StatusOr<SimLatticeFrame> frame = RenderSimLatticeFrame(*scene, c, 1);
    if (!frame.ok()) {
      state.SkipWithError(frame.status().ToString().c_str());
      return;
    }
    Detect(state, frame->bgr, with_prior ? &frame->truth : nullptr);
    return;
  }
  state.SkipWithError(("no case " + case_name).c_str());
}

void BM_Pop9Blind(benchmark::State& state) { DetectSim(state, "sim 3x3 varied", false); }
void BM_Pop9NearPrior(benchmark::State& state) { DetectSim(state, "sim 3x3 varied", true); }
void BM_Integral5x4Blind(benchmark::State& state) { DetectSim(state, "sim 5x4 varied", false); }
void BM_ActionSamplerBlind(benchmark::State& state) {
  SetThreads();
  StatusOr<cv::Mat> frame = LoadActionSamplerFrame(sim::SharedDataDir());
  if (!frame.ok()) {
    state.SkipWithError(frame.status().ToString().c_str());
    return;
  }
  Detect(state, *frame, nullptr);
}

BENCHMARK(BM_Pop9Blind)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Pop9NearPrior)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Integral5x4Blind)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ActionSamplerBlind)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace px::eval
