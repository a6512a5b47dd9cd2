// The table of frame sources the daemon can open by name. The only place in device/ that names
// concrete sources (STYLE.md section 2): "sim" (sim/synthetic), "replay" (sim/replay)
// and "libcamera" (drivers/libcamera).
// Hardware drivers join here as they land.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "device/config.h"
#include "drivers/source/frame_source.h"
#include "sim/synthetic/sim_camera.h"

namespace px::device {

struct OpenedSource {
  std::unique_ptr<FrameSource> source;
  // What to ask Configure for; nullopt: whatever the source delivers natively (a replay).
  std::optional<SourceConfig> wanted;
};

// The source kinds OpenSource knows, for help texts and errors.
std::vector<std::string> KnownSourceKinds();

// The simulated camera for the settings: the preset, with tile_width/tile_height overriding its
// tile size (0 keeps the preset's; one given alone keeps the preset's aspect ratio) and the
// focal length scaled with the tile width, so the field of view stays the preset's.
StatusOr<SimCameraSpec> SimCameraFromSettings(const SimSourceSettings& settings);

// Opens (but does not configure) the source the settings name, wrapped in the fault injector
// (sim/faults) when source.faults is not empty. Errors name the config field:
// "source.sim.scene: /x.json: no such file", "source.replay.path: ...".
StatusOr<OpenedSource> OpenSource(const SourceSettings& settings);

}  // namespace px::device
