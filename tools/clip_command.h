// `parallax clip RECORDING -o OUT.mp4` (or .gif, .webp, a PNG folder): the offline pipeline on a recording.
#pragma once

#include <CLI/CLI.hpp>

namespace px::cli {

void AddClipCommand(CLI::App& app);

}  // namespace px::cli
