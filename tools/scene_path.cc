#include "tools/scene_path.h"

#include "sim/synthetic/data_paths.h"

namespace px::cli {

StatusOr<std::filesystem::path> ResolveScenePath(const std::string& scene) {
  std::filesystem::path path(scene);
  if (scene.find('/') == std::string::npos && path.extension() != ".json") {
    path = sim::ScenesDir() / (scene + ".json");
  }
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    return NotFoundError("scene '" + scene + "': no file " + path.string());
  }
  return path;
}

}  // namespace px::cli
