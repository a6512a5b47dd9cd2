// Middlebury multi-view stereo sets (../shared/data/middlebury_mview_templeSparseRing, SOURCES.md
// 7): <name>_par.txt holds the image count, then per image `file k11..k33 r11..r33 t1 t2 t3`
// with P = K [R | t] (x right, y down, origin top-left): exact cameras from a calibrated gantry.
#pragma once

#include <filesystem>
#include <vector>

#include "pipeline/core/status.h"
#include "pipeline/core/view.h"

namespace px::eval {

// The views in file order, id = index, world = the gantry's frame (metres). Reads the one
// *_par.txt in `dir`; errors name the file and the line.
StatusOr<std::vector<View>> LoadMiddleburyMview(const std::filesystem::path& dir);

}  // namespace px::eval
