#include "device/source_registry.h"

#include <cmath>

#include "sim/replay/replay_source.h"
#include "sim/synthetic/synthetic_source.h"

namespace px::device {

std::vector<std::string> KnownSourceKinds() { return {"sim", "replay"}; }

StatusOr<SimCameraSpec> SimCameraFromSettings(const SimSourceSettings& settings) {
  SimCameraSpec spec;
  if (settings.camera == "pop9") {
    spec = SimCameraSpec::Pop9();
  } else if (settings.camera == "integral5x4") {
    spec = SimCameraSpec::Integral5x4();
  } else {
    return InvalidArgumentError("source.sim.camera: '" + settings.camera + "' is not one of pop9, integral5x4");
  }
  const int preset_width = spec.tile_width;
  const int preset_height = spec.tile_height;
  int width = settings.tile_width;
  int height = settings.tile_height;
  if (width == 0 && height > 0) width = static_cast<int>(std::lround(preset_width * double(height) / preset_height));
  if (height == 0 && width > 0) height = static_cast<int>(std::lround(preset_height * double(width) / preset_width));
  if (width > 0) {
    spec.focal_px *= static_cast<double>(width) / preset_width;
    spec.tile_width = width;
    spec.tile_height = height;
    spec.name += "-" + std::to_string(width) + "x" + std::to_string(height);
  }
  if (Status valid = spec.Validate(); !valid.ok()) return valid.WithContext("source.sim");
  return spec;
}

StatusOr<OpenedSource> OpenSource(const SourceSettings& settings) {
  OpenedSource opened;
  if (settings.kind == "sim") {
    SyntheticSourceOptions options;
    PX_ASSIGN_OR_RETURN(options.camera, SimCameraFromSettings(settings.sim));
    options.scene_file = settings.sim.scene;
    options.seed = settings.sim.seed;
    auto source = MakeSyntheticSource(options);
    if (!source.ok()) return source.status().WithContext("source.sim");
    opened.source = std::move(source).value();
    // The sensor's native size in the camera's own pixel format.
    SourceConfig wanted;
    wanted.pixel_format = options.camera.pixel_format;
    wanted.shots = 1;
    opened.wanted = wanted;
    return opened;
  }
  if (settings.kind == "replay") {
    ReplayOptions options;
    options.loop = settings.replay.loop;
    auto source = OpenReplaySource(settings.replay.path, options);
    if (!source.ok()) return source.status().WithContext("source.replay.path");
    opened.source = std::move(source).value();
    return opened;
  }
  return InvalidArgumentError("source.kind: '" + settings.kind + "' is not one of sim, replay");
}

}  // namespace px::device
