// `parallax sim`: renders a synthetic capture of a scene to a recording, with its ground truth.
#pragma once

#include <CLI/CLI.hpp>

namespace px::cli {

void AddSimCommand(CLI::App& app);

}  // namespace px::cli
