// `parallax batch INPUT... -o DIR` and `parallax rerender STORE -o DIR`: a clip of every input
// (or of every raw capture in the daemon's store) with the same clip flags, resumable
// (batch_runner.h).
#pragma once

#include <CLI/CLI.hpp>

namespace px::cli {

void AddBatchCommands(CLI::App& app);

}  // namespace px::cli
