// Helpers shared by the sim/synthetic tests (test binaries only).
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "sim/synthetic/data_paths.h"
#include "sim/synthetic/scene_json.h"
#include "sim/synthetic/sim_camera.h"
#include "tests/testing/temp_dir.h"

namespace px::sim::testing {

using px::testing::TempDir;

inline void WriteText(const std::filesystem::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary);
  out << text;
}

inline std::filesystem::path SceneFile(const std::string& name) { return ScenesDir() / (name + ".json"); }

// The preset's geometry at a quarter of the pixels: same field of view, same baseline.
inline SimCameraSpec Quartered(SimCameraSpec spec) {
  spec.tile_width /= 2;
  spec.tile_height /= 2;
  spec.focal_px /= 2;
  spec.gap_px /= 2;
  return spec;
}

}  // namespace px::sim::testing
