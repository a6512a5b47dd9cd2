// The consistent blend's options (pipeline/render/consistent_blend_options.h) as command-line
// flags, shared by the commands that render (eval render, eval real).
#pragma once

#include <CLI/CLI.hpp>

#include "pipeline/render/consistent_blend_options.h"

namespace px::cli {

void AddConsistentBlendFlags(CLI::App& command, ConsistentBlendOptions* options);

}  // namespace px::cli
