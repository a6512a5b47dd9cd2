// `parallax eval real`: the product scored on real captures (eval/real).
#pragma once

#include <CLI/CLI.hpp>

namespace px::cli {

void AddEvalRealCommand(CLI::App& eval);

}  // namespace px::cli
