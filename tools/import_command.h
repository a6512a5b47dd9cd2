// `parallax import`: photos taken elsewhere (hand-held, from a phone or a camera's card) as a
// recording, so `parallax clip` and the daemon's replay treat them as the USB camera's shots.
#pragma once

#include <CLI/CLI.hpp>

namespace px::cli {

void AddImportCommand(CLI::App& app);

}  // namespace px::cli
