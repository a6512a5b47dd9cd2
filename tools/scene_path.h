// Resolves a scene argument: a bare name means sim/scenes/<name>.json, anything else is a path.
#pragma once

#include <filesystem>
#include <string>

#include "pipeline/core/status.h"

namespace px::cli {

StatusOr<std::filesystem::path> ResolveScenePath(const std::string& scene);

}  // namespace px::cli
