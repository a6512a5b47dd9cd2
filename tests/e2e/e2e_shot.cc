#include "tests/e2e/e2e_shot.h"

#include <chrono>
#include <cmath>

#include "sim/synthetic/data_paths.h"
#include "sim/synthetic/synthetic_source.h"

namespace px::e2e {

SimCameraSpec Pop9Spec(double tile_scale, PixelFormat format) {
  SimCameraSpec spec = SimCameraSpec::Pop9();
  spec.tile_width = static_cast<int>(std::lround(spec.tile_width * tile_scale));
  spec.tile_height = static_cast<int>(std::lround(spec.tile_height * tile_scale));
  spec.focal_px *= tile_scale;
  spec.pixel_format = format;
  return spec;
}

std::filesystem::path ScenePath(const std::string& name) { return sim::ScenesDir() / (name + ".json"); }

StatusOr<SimulatedShot> CaptureShot(const SimCameraSpec& spec, const std::string& scene, uint64_t seed) {
  SimulatedShot shot;
  shot.spec = spec;
  shot.scene_file = ScenePath(scene);
  SyntheticSourceOptions options;
  options.camera = spec;
  options.scene_file = shot.scene_file;
  options.seed = seed;
  PX_ASSIGN_OR_RETURN(auto source, MakeSyntheticSource(options));
  SourceConfig wanted;
  wanted.pixel_format = spec.pixel_format;
  SourceConfig granted;
  PX_ASSIGN_OR_RETURN(ConfigureResult configured, source->Configure(wanted, &granted));
  (void)configured;
  PX_ASSIGN_OR_RETURN(shot.capture, source->Next(std::chrono::milliseconds(600000)));
  shot.rig = *source->Describe().rig;
  PX_ASSIGN_OR_RETURN(shot.truth, LastGroundTruth(*source));
  return shot;
}

}  // namespace px::e2e
