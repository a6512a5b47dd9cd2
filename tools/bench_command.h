// `parallax bench`: the standard shot end to end (simulated Pop9, 9 views of 640x480, a 5 s clip
// at 30 fps), printing milliseconds per stage, the total and peak RSS.
#pragma once

#include <CLI/CLI.hpp>

namespace px::cli {

void AddBenchCommand(CLI::App& app);

}  // namespace px::cli
