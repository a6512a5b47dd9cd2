// `parallax eval <what>`: the evaluation tools, each against ground truth or reference data, each
// printing a table (or JSON with --json) for every dataset it knows, with --data DIR for any
// folder in the same layout. One file per tool (eval_<what>_command.cc) registers itself here.
#pragma once

#include <CLI/CLI.hpp>

namespace px::cli {

void AddEvalCommand(CLI::App& app);

}  // namespace px::cli
