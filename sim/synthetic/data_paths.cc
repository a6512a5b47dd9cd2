#include "sim/synthetic/data_paths.h"

#include <cstdlib>

#ifndef PX_DEFAULT_DATA_DIR
#error "PX_DEFAULT_DATA_DIR must be defined by the build (sim/synthetic/CMakeLists.txt)"
#endif
#ifndef PX_DEFAULT_SCENES_DIR
#error "PX_DEFAULT_SCENES_DIR must be defined by the build (sim/synthetic/CMakeLists.txt)"
#endif

namespace px::sim {
namespace {

std::filesystem::path FromEnvironment(const char* variable, const char* fallback) {
  const char* value = std::getenv(variable);
  if (value != nullptr && value[0] != '\0') return std::filesystem::path(value);
  return std::filesystem::path(fallback).lexically_normal();
}

}  // namespace

std::filesystem::path SharedDataDir() { return FromEnvironment("PX_DATA_DIR", PX_DEFAULT_DATA_DIR); }

std::filesystem::path ScenesDir() { return FromEnvironment("PX_SCENES_DIR", PX_DEFAULT_SCENES_DIR); }

}  // namespace px::sim
