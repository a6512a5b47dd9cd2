// The shots `parallax bench` times: the standard shot and captures at the resolutions people use
// (a 12 MP lattice sensor, four 12 MP phone photos, a 20-lens integral camera), each with the
// clip size its owner wants.
#pragma once

#include <string>
#include <vector>

#include "pipeline/core/status.h"
#include "sim/synthetic/handheld_photos.h"
#include "sim/synthetic/sim_camera.h"

namespace px::cli {

struct BenchPreset {
  std::string name;
  std::string description;
  // A lattice camera delivers one frame through `camera`; a hand-held set is `photos` written
  // as JPEG files, then imported as `parallax clip FOLDER` imports them.
  bool handheld = false;
  SimCameraSpec camera;
  sim::HandHeldPhotoOptions photos;
  std::string size;  // the clip's "WxH"; "" = the views' size
  double duration_s = 5.0;
  double fps = 30.0;
};

const std::vector<BenchPreset>& BenchPresets();
// NOT_FOUND naming the presets there are.
StatusOr<BenchPreset> FindBenchPreset(const std::string& name);
// "standard, pop9-12mp, ..." for --help.
std::string BenchPresetNames();

}  // namespace px::cli
