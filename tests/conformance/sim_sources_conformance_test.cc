// The conformance suite over the sources that always run: the simulated camera (3x3 and 5x4,
// several pixel formats) and the replay of recordings.
#include <filesystem>
#include <string>

#include "capture/recording.h"
#include "sim/replay/replay_source.h"
#include "sim/synthetic/data_paths.h"
#include "sim/synthetic/synthetic_source.h"
#include "tests/conformance/frame_source_conformance.h"

namespace px::conformance {
namespace {

using std::chrono::milliseconds;

// Small cameras keep the suite fast; the geometry is the same as the full-size presets.
SimCameraSpec SmallPop9() {
  SimCameraSpec spec = SimCameraSpec::Pop9();
  spec.tile_width = 160;
  spec.tile_height = 120;
  spec.focal_px = 140;
  spec.gap_px = 6;
  spec.supersampling = 1;
  return spec;
}

SimCameraSpec SmallIntegral() {
  SimCameraSpec spec = SimCameraSpec::Integral5x4();
  spec.tile_width = 96;
  spec.tile_height = 72;
  spec.focal_px = 84;
  spec.gap_px = 4;
  spec.supersampling = 1;
  return spec;
}

std::filesystem::path Scene(const std::string& name) { return sim::ScenesDir() / (name + ".json"); }

StatusOr<std::unique_ptr<FrameSource>> MakeSim(const SimCameraSpec& spec, PixelFormat format, Clock* clock) {
  SyntheticSourceOptions options;
  options.camera = spec;
  options.camera.pixel_format = format;
  options.scene_file = Scene("still_life");
  options.clock = clock;
  return MakeSyntheticSource(options);
}

// A replay source over two recordings captured from the simulated camera.
StatusOr<std::unique_ptr<FrameSource>> MakeReplay(const std::filesystem::path& dir, Clock* clock) {
  PX_ASSIGN_OR_RETURN(auto sim, MakeSim(SmallPop9(), PixelFormat::kRgb888, clock));
  SourceConfig granted;
  PX_ASSIGN_OR_RETURN(ConfigureResult configured, sim->Configure(SourceConfig{PixelFormat::kRgb888}, &granted));
  (void)configured;
  for (int i = 0; i < 2; ++i) {
    PX_ASSIGN_OR_RETURN(FrameSet frames, sim->Next(milliseconds(10000)));
    Recording recording;
    recording.source = sim->Describe();
    recording.frames = std::move(frames);
    recording.created_by = "conformance test";
    PX_RETURN_IF_ERROR(WriteRecording(dir / ("shot_" + std::to_string(i)), recording));
  }
  return OpenReplaySource(dir);
}

std::vector<SourceCase> AllSources() {
  return {
      {"sim_pop9_rgb", [](const auto&, Clock* c) { return MakeSim(SmallPop9(), PixelFormat::kRgb888, c); }},
      {"sim_pop9_nv12", [](const auto&, Clock* c) { return MakeSim(SmallPop9(), PixelFormat::kNv12, c); }},
      {"sim_integral_bayer",
       [](const auto&, Clock* c) { return MakeSim(SmallIntegral(), PixelFormat::kBayerRggb8, c); }},
      {"replay", [](const auto& dir, Clock* c) { return MakeReplay(dir, c); }},
  };
}

INSTANTIATE_TEST_SUITE_P(Simulated, FrameSourceConformance, ::testing::ValuesIn(AllSources()), SourceCaseName);

}  // namespace
}  // namespace px::conformance
