// Speed of calibration (issue 3 goal: a 9-view 640x480 shot, refinement included, under 2 s on
// 2 cores): per-shot refinement of a simulated Pop9 shot whose lenses moved (features, guided
// matching, RANSAC, tracks, bundle adjustment) plus the undistorted views; and hand-held
// structure from motion on the 4-view sets of ../shared/data/handheld (skipped without them).
// Run: ./build/bench/calib_benchmark
#include <benchmark/benchmark.h>

#include "eval/calib/sim_lattice_shot.h"
#include "eval/datasets/image_folder.h"
#include "pipeline/calib/incremental_sfm.h"
#include "pipeline/calib/make_views.h"
#include "pipeline/calib/rig_refinement.h"
#include "pipeline/core/log.h"
#include "sim/synthetic/data_paths.h"

namespace px::eval {
namespace {

void BM_RefinePop9Shot(benchmark::State& state) {
  (void)SetLogLevels("warn");
  StatusOr<LatticeShot> shot = CaptureLatticeShot(RealisticSpec(SimCameraSpec::Pop9(), 3), "still_life");
  if (!shot.ok()) {
    state.SkipWithError(shot.status().ToString().c_str());
    return;
  }
  calib::RigRefinementOptions options;
  bool refined = false;
  for (auto _ : state) {
    StatusOr<calib::RigRefinementResult> result = calib::RefineRigCalibration(shot->tiles, shot->factory, options);
    if (!result.ok()) {
      state.SkipWithError(result.status().ToString().c_str());
      return;
    }
    StatusOr<std::vector<View>> views = MakeViews(shot->tiles, result->rig, CalibOptions());
    benchmark::DoNotOptimize(views);
    refined = result->report.refined;
  }
  state.counters["refined"] = refined ? 1 : 0;
}
BENCHMARK(BM_RefinePop9Shot)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);

void BM_HandHeldSfm(benchmark::State& state, const char* set) {
  (void)SetLogLevels("warn");
  StatusOr<std::vector<FolderImage>> images = LoadImageFolder(sim::SharedDataDir() / "handheld" / set);
  if (!images.ok()) {
    state.SkipWithError(images.status().ToString().c_str());
    return;
  }
  std::vector<calib::SfmImage> input;
  for (const FolderImage& image : *images) {
    calib::SfmImage sfm_image;
    sfm_image.image = image.bgr;
    if (image.focal_px > 0) sfm_image.intrinsics = CameraModel::Pinhole(image.bgr.cols, image.bgr.rows, image.focal_px);
    input.push_back(sfm_image);
  }
  int registered = 0;
  for (auto _ : state) {
    StatusOr<calib::SfmResult> result = calib::RunIncrementalSfm(input, calib::SfmOptions());
    if (!result.ok()) {
      state.SkipWithError(result.status().ToString().c_str());
      return;
    }
    registered = result->report.num_registered;
  }
  state.counters["registered"] = registered;
  state.counters["images"] = static_cast<double>(input.size());
}
BENCHMARK_CAPTURE(BM_HandHeldSfm, frenchpress_4views, "kpankov_frenchpress_4views")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(2);
BENCHMARK_CAPTURE(BM_HandHeldSfm, office_4views, "kpankov_office_4views")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(2);

}  // namespace
}  // namespace px::eval
