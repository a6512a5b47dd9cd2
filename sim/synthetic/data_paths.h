// Where the simulator finds its inputs: the shared real-data folder (face photos, textures)
// and the scene files. Environment variables override the build-time defaults so tests and
// deployments can point elsewhere without rebuilding.
#pragma once

#include <filesystem>

namespace px::sim {

// $PX_DATA_DIR if set and non-empty, else "<source root>/../shared/data" (fixed at build time).
// The folder may not exist: callers that need it check and fall back or skip.
std::filesystem::path SharedDataDir();

// $PX_SCENES_DIR if set and non-empty, else "<source root>/sim/scenes".
std::filesystem::path ScenesDir();

}  // namespace px::sim
