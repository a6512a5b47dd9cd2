// Helpers shared by the sim/synthetic tests (test binaries only).
#pragma once

#include <gtest/gtest.h>
#include <stdlib.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "sim/synthetic/data_paths.h"
#include "sim/synthetic/scene_json.h"
#include "sim/synthetic/sim_camera.h"

namespace px::sim::testing {

// A fresh folder per test, removed afterwards.
class TempDir {
 public:
  TempDir() {
    std::string pattern = (std::filesystem::temp_directory_path() / "px_sim_test_XXXXXX").string();
    const char* made = mkdtemp(pattern.data());
    EXPECT_NE(made, nullptr) << "mkdtemp failed";
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

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
