// Shared setup for the end-to-end tests: a simulated Pop9 capture of a scene, with its truth.
#pragma once

#include <filesystem>
#include <string>

#include "pipeline/core/frame_set.h"
#include "pipeline/core/rig_calibration.h"
#include "sim/synthetic/sim_camera.h"
#include "sim/synthetic/sim_sensor.h"

namespace px::e2e {

struct SimulatedShot {
  SimCameraSpec spec;
  std::filesystem::path scene_file;
  FrameSet capture;
  RigCalibration rig;
  sim::GroundTruth truth;
};

// The product's Pop9 geometry; `tile_scale` shrinks tiles and focal length together (1 = 640x480).
SimCameraSpec Pop9Spec(double tile_scale, PixelFormat format = PixelFormat::kRgb888);

std::filesystem::path ScenePath(const std::string& name);

// Captures one frame set from the synthetic source, with the source's calibration and truth.
StatusOr<SimulatedShot> CaptureShot(const SimCameraSpec& spec, const std::string& scene, uint64_t seed = 1);

}  // namespace px::e2e
