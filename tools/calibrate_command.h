// `parallax calibrate`: factory rig calibration from captures of a checkerboard seen through
// every lens; writes the rig calibration JSON.
#pragma once

#include <CLI/CLI.hpp>

namespace px::cli {

void AddCalibrateCommand(CLI::App& app);

}  // namespace px::cli
