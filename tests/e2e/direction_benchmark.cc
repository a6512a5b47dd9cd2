// Path planning time of the direction stage (issue 6, item 11: under 1 s for a 9-view shot on 2
// cores) on simulated Pop9 shots of the product's size (9 views of 640x480) with 0, 1 and 2 faces:
// PlanCameraPath with the simulator's true depth and the CPU renderer's Coverage. Counters: face
// detection ms, coverage probes and their ms, the move chosen (as its row: subjects it needs).
// Prints the path chosen and why (stderr); asserts nothing. The face scenes need ../shared/data/faces_dlib_pascalvoc (else their
// procedural fallback textures, which the cascades do not take for faces).
#include <benchmark/benchmark.h>

#include <cstdio>
#include <map>
#include <memory>

#include "device/face_cascades.h"
#include "pipeline/direct/taxonomy.h"
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

// range(0): faces in the scene (0 still_life, 1 one_face, 2 two_faces).
void BM_PlanCameraPath(benchmark::State& state) {
  static const char* kScenes[] = {"still_life", "one_face", "two_faces"};
  e2e::DirectionShot* shot = GetShot(kScenes[state.range(0)]);
  auto detector = device::LoadFaceDetector();
  if (shot == nullptr || !detector.ok()) {
    state.SkipWithError("no shot or no face cascades (opencv-data)");
    return;
  }
  DirectOptions options;  // the product's defaults: 5 s at 30 fps, move and effect drawn
  DirectionContext context;
  context.face_detector = detector->get();
  context.coverage = shot->Coverage();
  DirectionReport report;
  std::string move, why;
  for (auto _ : state) {
    StatusOr<CameraPath> path = PlanCameraPath(shot->views, shot->depths, options, context, &report);
    if (!path.ok()) {
      state.SkipWithError(path.status().ToString().c_str());
      return;
    }
    move = path->move;
    why = path->reason;
    for (const std::string& note : path->notes) why += "\n    " + note;
  }
  std::fprintf(stderr, "  %s: %s\n", kScenes[state.range(0)], why.c_str());
  state.counters["subjects_ms"] = report.subjects_ms;
  state.counters["coverage_ms"] = report.coverage_ms;
  state.counters["probes"] = report.coverage_probes;
  state.counters["verify_probes"] = report.verify_probes;
  state.counters["verify_ms"] = report.verify_ms;
  state.counters["subjects"] = report.num_subjects;
  state.counters["fell_back"] = report.fell_back ? 1 : 0;
  state.SetLabel(std::string(kScenes[state.range(0)]) + ": " + move);
}
BENCHMARK(BM_PlanCameraPath)->ArgNames({"faces"})->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace px
