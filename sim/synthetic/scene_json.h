// Scene files: JSON describing materials and objects (format in sim/scenes/FORMAT.md).
// Errors name the file and the JSON path: "/s/x.json: objects[2].radius_m: want a number, got string".
#pragma once

#include <filesystem>
#include <nlohmann/json_fwd.hpp>
#include <string>

#include "pipeline/core/status.h"
#include "sim/synthetic/scene.h"

namespace px::sim {

// Reads and parses a scene file. Texture paths starting with "data:" are relative to
// SharedDataDir(), others to the scene file's folder. A missing texture file is NOT_FOUND
// (naming it) unless the material names a "fallback", which is then used with a warning
// (logged and kept in Scene::warnings).
StatusOr<Scene> LoadScene(const std::filesystem::path& file);

// Parses scene JSON text; `base_dir` resolves relative texture paths and `what` names the
// source in errors (usually the file name).
StatusOr<Scene> ParseScene(const std::string& text, const std::filesystem::path& base_dir, const std::string& what);
StatusOr<Scene> ParseSceneJson(const nlohmann::json& j, const std::filesystem::path& base_dir, const std::string& what);

}  // namespace px::sim
