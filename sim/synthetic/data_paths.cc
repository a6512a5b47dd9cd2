#include "sim/synthetic/data_paths.h"

#include <cstdlib>
#include <fstream>
#include <optional>
#include <string>
#include <system_error>

namespace px::sim {
namespace {

namespace fs = std::filesystem;

// The source folder of the build tree the running executable lies in: the CMakeCache.txt at or
// above the executable's folder names it (CMAKE_HOME_DIRECTORY). nullopt for an installed program.
std::optional<fs::path> SourceOfBuildTree() {
  std::error_code ec;
  const fs::path executable = fs::read_symlink("/proc/self/exe", ec);
  if (ec) return std::nullopt;
  for (fs::path dir = executable.parent_path(); !dir.empty(); dir = dir.parent_path()) {
    std::ifstream cache(dir / "CMakeCache.txt");
    const std::string key = "CMAKE_HOME_DIRECTORY:INTERNAL=";
    for (std::string line; cache && std::getline(cache, line);) {
      if (line.rfind(key, 0) == 0) return fs::path(line.substr(key.size()));
    }
    if (dir == dir.root_path()) break;
  }
  return std::nullopt;
}

fs::path FromEnvironment(const char* variable, const fs::path& beside_source) {
  const char* value = std::getenv(variable);
  if (value != nullptr && value[0] != '\0') return fs::path(value);
  static const std::optional<fs::path> source = SourceOfBuildTree();
  if (!source) return {};
  return (*source / beside_source).lexically_normal();
}

}  // namespace

fs::path SharedDataDir() { return FromEnvironment("PX_DATA_DIR", fs::path("..") / "shared" / "data"); }

fs::path ScenesDir() { return FromEnvironment("PX_SCENES_DIR", fs::path("sim") / "scenes"); }

}  // namespace px::sim
