// The fade of stretched segments (pipeline/render/texture_stretch.h) as command-line flags, shared
// by the commands that score rendering (eval render, eval real).
#pragma once

#include <CLI/CLI.hpp>

#include "pipeline/render/texture_stretch.h"

namespace px::cli {

void AddTextureStretchFlags(CLI::App& command, TextureStretchOptions* options);

}  // namespace px::cli
