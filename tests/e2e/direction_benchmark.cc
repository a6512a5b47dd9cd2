// Path planning time of the direction stage (issue 6, item 11: under 1 s for a 9-view shot on 2
// cores) on simulated Pop9 shots of the product's size (9 views of 640x480) with 0, 1 and 2 faces:
// PlanCameraPath with the simulator's true depth and the CPU renderer's Coverage. Counters: face
// detection ms, coverage probes and their ms, the move chosen (as its row: subjects it needs).
// Faces are detected once before planning (as the pipeline does, beside the depth stage); plan_ms
// is the planning's wall time, plan_cpu_ms its process CPU time (all threads: comparable on a
// loaded machine). Prints the path chosen and why (stderr); asserts nothing. range(1) = 0 searches with the
// renderer's Coverage at 1/8 size (the default), 1 with the splat (splat_coverage.h).
// BM_SearchProbeAgreement prints how often the search's probes agree with the renderer at the
// output size. The face scenes need ../shared/data/faces_dlib_pascalvoc (else their procedural
// fallback textures, which the cascades do not take for faces).
#include <benchmark/benchmark.h>

#include <cstdio>
#include <ctime>
#include <map>
#include <memory>

#include "device/face_cascades.h"
#include "pipeline/direct/scene_geometry.h"
#include "pipeline/direct/splat_coverage.h"
#include "pipeline/direct/subjects.h"
#include "pipeline/direct/taxonomy.h"
#include "pipeline/direct/valid_viewpoints.h"
#include "tests/e2e/direction_shot.h"

namespace px {
namespace {

// Shots are built once per scene: simulating 9 views of 640x480 takes seconds.
e2e::DirectionShot* GetShot(const std::string& scene) {
  static std::map<std::string, std::unique_ptr<e2e::DirectionShot>> shots;
  auto& shot = shots[scene];
  if (!shot) {
    auto made = e2e::MakeDirectionShot(scene, 1.0);
    if (!made.ok()) return nullptr;
    shot = std::move(made).value();
  }
  return shot.get();
}

constexpr int kSplatStride = 8;  // every 8th pixel of each view: ~43k points for 9 views of 640x480

// range(0): faces in the scene (0 still_life, 1 one_face, 2 two_faces); range(1): the search's
// probe, 1 the splat, 0 the renderer at 1/8 size (the default).
void BM_PlanCameraPath(benchmark::State& state) {
  static const char* kScenes[] = {"still_life", "one_face", "two_faces"};
  e2e::DirectionShot* shot = GetShot(kScenes[state.range(0)]);
  auto detector = device::LoadFaceDetector();
  if (shot == nullptr || !detector.ok()) {
    state.SkipWithError("no shot or no face cascades (opencv-data)");
    return;
  }
  DirectOptions options;  // the product's defaults: 5 s at 30 fps, move and effect drawn
  options.search.splat_stride = state.range(1) == 0 ? 0 : kSplatStride;
  // As in the pipeline (pipeline/run), the centre view's faces are found beside the depth stage,
  // before planning: detected once here, outside the timed loop.
  const View& centre = shot->views[direct::CentreViewIndex(shot->views)];
  const direct::DetectedFaces faces = direct::DetectFaces(centre.image, centre.id, **detector, options.faces);
  DirectionContext context;
  context.face_detector = detector->get();
  context.centre_faces = &faces;
  context.coverage = shot->Coverage();
  context.coverage_concurrent = true;  // CpuSceneRenderer::Coverage
  DirectionReport report;
  std::string move, why;
  double cpu_ms = 0;
  for (auto _ : state) {
    const std::clock_t cpu_start = std::clock();  // process CPU: every thread, comparable under load
    StatusOr<CameraPath> path = PlanCameraPath(shot->views, shot->depths, options, context, &report);
    cpu_ms += 1000.0 * static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
    if (!path.ok()) {
      state.SkipWithError(path.status().ToString().c_str());
      return;
    }
    move = path->move;
    why = path->reason;
    for (const std::string& note : path->notes) why += "\n    " + note;
  }
  std::fprintf(
      stderr, "  %s (%s search): %s\n", kScenes[state.range(0)], state.range(1) ? "splat" : "renderer", why.c_str());
  state.counters["faces_ms"] = faces.ms;  // the detection beside depth, not part of planning
  // Planning (placing the faces found, choosing and checking the path): wall, and the process's
  // CPU time over all threads, per plan.
  state.counters["plan_ms"] = report.total_ms;
  state.counters["plan_cpu_ms"] = cpu_ms / static_cast<double>(state.iterations());
  state.counters["parallax_pct"] = 100 * report.plan.parallax;
  state.counters["max_h"] = report.plan.max_hole_score;
  state.counters["coverage_ms"] = report.coverage_ms;
  state.counters["probes"] = report.coverage_probes;
  state.counters["verify_probes"] = report.verify_probes;
  state.counters["verify_ms"] = report.verify_ms;
  state.counters["subjects"] = report.num_subjects;
  state.counters["fell_back"] = report.fell_back ? 1 : 0;
  state.SetLabel(std::string(kScenes[state.range(0)]) + ": " + move);
}
BENCHMARK(BM_PlanCameraPath)
    ->ArgNames({"faces", "splat"})
    ->ArgsProduct({{0, 1, 2}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// How often the region search's probes agree with the renderer's Coverage at the output size
// (the verification's judge) on valid (H < 2) or not: the splat (splat_coverage.h) and the
// renderer at 1/8 size (the search's probe before it). Viewpoints: a 6 x 6 grid over twice the
// viewpoints' box, at six depths between the farthest back and forward positions searched,
// aimed at the scene centroid at f. Printed per scene with each probe's mean time.
void BM_SearchProbeAgreement(benchmark::State& state) {
  static const char* kScenes[] = {"still_life", "one_face", "two_faces"};
  e2e::DirectionShot* shot = GetShot(kScenes[state.range(0)]);
  if (shot == nullptr) {
    state.SkipWithError("no shot");
    return;
  }
  StatusOr<direct::SceneGeometry> scene = direct::DescribeScene(shot->views, shot->depths);
  if (!scene.ok()) {
    state.SkipWithError(scene.status().ToString().c_str());
    return;
  }
  DirectOptions options;
  options.search.grid_size = 6;
  const direct::ZLimits z = direct::SearchLimits(*scene, options.search);
  const std::vector<Eigen::Vector2d> grid = direct::GridPositions(*scene, options.search).value();
  const direct::SplatCoverage splat =
      direct::SplatCoverage::FromDepths(shot->views, shot->depths, options.search.search_scale, kSplatStride);
  const CoverageFunction splat_function = splat.AsFunction(), renderer = shot->Coverage();
  direct::CoverageProbe splat_probe(&splat_function, 1.0, 2.0);
  direct::CoverageProbe small_probe(&renderer, options.search.search_scale, 2.0);
  direct::CoverageProbe full_probe(&renderer, 1.0, 2.0);
  const CameraModel camera = scene->OutputWithFocal(scene->focal_px);
  int samples = 0, splat_agrees = 0, small_agrees = 0, full_valid = 0, splat_optimistic = 0, small_optimistic = 0;
  for (auto _ : state) {
    for (double zf : {-1.0, -0.5, -0.2, 0.0, 0.4, 0.8}) {
      const double z_m = zf < 0 ? zf * z.back_m : zf * z.forward_m;
      for (const Eigen::Vector2d& xy : grid) {
        const Eigen::Vector3d centre = scene->WorldFromRig(Eigen::Vector3d(xy.x(), xy.y(), z_m));
        const Rigid3 pose = Rigid3::LookAt(centre, scene->centroid_in_world, scene->up_in_world);
        const bool truth = full_probe.Valid(camera, pose).value();
        const bool by_splat = splat_probe.Valid(camera, pose).value();
        const bool by_small = small_probe.Valid(camera, pose).value();
        ++samples;
        full_valid += truth;
        splat_agrees += by_splat == truth;
        small_agrees += by_small == truth;
        splat_optimistic += by_splat && !truth;
        small_optimistic += by_small && !truth;
      }
    }
  }
  std::fprintf(stderr,
               "  %s: %d viewpoints (%d valid at 640x480): splat agrees %.0f%% (%d read valid wrongly), %.2f ms a "
               "probe; renderer at 1/8 agrees %.0f%% (%d read valid wrongly), %.2f ms a probe; full size %.1f ms\n",
               kScenes[state.range(0)],
               samples,
               full_valid,
               100.0 * splat_agrees / samples,
               splat_optimistic,
               splat_probe.ms() / splat_probe.calls(),
               100.0 * small_agrees / samples,
               small_optimistic,
               small_probe.ms() / small_probe.calls(),
               full_probe.ms() / full_probe.calls());
  state.counters["splat_agree_pct"] = 100.0 * splat_agrees / samples;
  state.counters["small_agree_pct"] = 100.0 * small_agrees / samples;
  state.counters["splat_ms"] = splat_probe.ms() / splat_probe.calls();
  state.counters["small_ms"] = small_probe.ms() / small_probe.calls();
  state.SetLabel(kScenes[state.range(0)]);
}
BENCHMARK(BM_SearchProbeAgreement)
    ->ArgNames({"faces"})
    ->Arg(0)
    ->Arg(1)
    ->Arg(2)
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace px
