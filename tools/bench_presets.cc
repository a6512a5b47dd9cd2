#include "tools/bench_presets.h"

namespace px::cli {
namespace {

// `spec` on a sensor whose tiles are `width` x `height`: the same field of view, so the focal
// length scales with the tile's width.
SimCameraSpec WithTiles(SimCameraSpec spec, int width, int height) {
  spec.focal_px *= static_cast<double>(width) / spec.tile_width;
  spec.tile_width = width;
  spec.tile_height = height;
  return spec;
}

BenchPreset LatticePreset(std::string name, std::string description, SimCameraSpec camera, std::string size) {
  BenchPreset preset;
  preset.name = std::move(name);
  preset.description = std::move(description);
  preset.camera = std::move(camera);
  preset.size = std::move(size);
  return preset;
}

std::vector<BenchPreset> MakePresets() {
  std::vector<BenchPreset> presets;
  presets.push_back(LatticePreset(
      "standard", "simulated Pop9, 9 views of 640x480, a 640x480 clip", SimCameraSpec::Pop9(), /*size=*/""));
  presets.push_back(LatticePreset("pop9-12mp",
                                  "simulated Pop9 on a 12 MP sensor, 9 views of 1330x1000, a 1920x1080 clip",
                                  WithTiles(SimCameraSpec::Pop9(), 1330, 1000),
                                  "1920x1080"));
  BenchPreset handheld;
  handheld.name = "handheld-4x12mp";
  handheld.description = "four simulated hand-held photos of 4000x3000 (JPEG, EXIF focal), a 1080x1920 clip";
  handheld.handheld = true;
  handheld.photos.width = 4000;
  handheld.photos.height = 3000;
  handheld.photos.shots = 4;
  handheld.size = "1080x1920";
  presets.push_back(handheld);
  presets.push_back(
      LatticePreset("integral-20",
                    "simulated 5x4 integral lens on a 10 MP sensor, 20 views of 800x600, a 1920x1080 clip",
                    WithTiles(SimCameraSpec::Integral5x4(), 800, 600),
                    "1920x1080"));
  return presets;
}

}  // namespace

const std::vector<BenchPreset>& BenchPresets() {
  static const std::vector<BenchPreset> presets = MakePresets();
  return presets;
}

std::string BenchPresetNames() {
  std::string names;
  for (const BenchPreset& preset : BenchPresets()) names += (names.empty() ? "" : ", ") + preset.name;
  return names;
}

StatusOr<BenchPreset> FindBenchPreset(const std::string& name) {
  for (const BenchPreset& preset : BenchPresets()) {
    if (preset.name == name) return preset;
  }
  return NotFoundError("--preset '" + name + "' is not one of " + BenchPresetNames());
}

}  // namespace px::cli
