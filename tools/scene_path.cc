#include "tools/scene_path.h"

#include "sim/synthetic/data_paths.h"

namespace px::cli {

StatusOr<std::filesystem::path> ResolveScenePath(const std::string& scene) {
  std::filesystem::path path(scene);
  if (scene.find('/') == std::string::npos && path.extension() != ".json") {
    if (sim::ScenesDir().empty()) {
      return NotFoundError("scene '" + scene +
                           "': a scene by name needs the scenes folder (PX_SCENES_DIR, or run from a build tree); "
                           "or give the scene file's path");
    }
    path = sim::ScenesDir() / (scene + ".json");
  }
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    return NotFoundError("scene '" + scene + "': no file " + path.string());
  }
  return path;
}

}  // namespace px::cli
