// Where the simulator finds its inputs: the shared real-data folder (face photos, textures)
// and the scene files. Nothing is compiled in: environment variables name them, and a program
// run from a checkout's build tree finds them beside that checkout (tests, tools, the demo).
#pragma once

#include <filesystem>

namespace px::sim {

// $PX_DATA_DIR if set and non-empty; else, for a program in a build tree, "<source>/../shared/data"
// (the source named by the tree's CMakeCache.txt); else empty. The folder may not exist: callers
// that need it check and fall back or skip.
std::filesystem::path SharedDataDir();

// $PX_SCENES_DIR if set and non-empty; else, from a build tree, "<source>/sim/scenes"; else empty.
std::filesystem::path ScenesDir();

}  // namespace px::sim
