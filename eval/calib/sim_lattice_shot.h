// A simulated lattice shot for calibration tests and evaluation: the upright tiles as the lattice stage
// cuts them from the noisy sensor frame, the factory calibration the recording carries, and the
// truth (perturbed lenses) the views were rendered through.
#pragma once

#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "pipeline/core/rig_calibration.h"
#include "sim/synthetic/sim_camera.h"

namespace px::eval {

struct LatticeShot {
  cv::Mat sensor;              // the raw sensor frame (BGR) the tiles were cut from
  std::vector<cv::Mat> tiles;  // upright, as the lenses saw them (noise, vignetting, gains)
  RigCalibration factory;      // what the recording carries
  RigCalibration truth;        // what the views were rendered through
};

// A camera with realistic sensor defects (noise sigma 2, vignetting 0.3, gains +-5 %) and the
// given lens perturbation seed (0 = lenses as calibrated).
SimCameraSpec RealisticSpec(SimCameraSpec spec, uint64_t perturb_lenses_seed);

// The preset at half the tile size (same field of view and baseline): four times cheaper.
SimCameraSpec HalfSize(SimCameraSpec spec);

// `scene` names a scene in sim/scenes or is a path to a scene JSON.
StatusOr<LatticeShot> CaptureLatticeShot(const SimCameraSpec& spec, const std::string& scene, uint64_t seed = 1);

// One textured or flat plane facing the camera at `distance_m` (for degenerate scenes): writes
// the scene JSON to `file`. `material_json` is a scene material object.
void WritePlaneScene(const std::filesystem::path& file, double distance_m, const std::string& material_json);

}  // namespace px::eval
