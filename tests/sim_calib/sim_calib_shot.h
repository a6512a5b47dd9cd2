// A simulated lattice shot for the calibration tests: the upright tiles as the lattice stage
// cuts them from the noisy sensor frame, the factory calibration the recording carries, and the
// truth (perturbed lenses) the views were rendered through.
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "pipeline/core/rig_calibration.h"
#include "sim/synthetic/sim_camera.h"

namespace px::sim_calib {

struct LatticeShot {
  std::vector<cv::Mat> tiles;  // upright, as the lenses saw them (noise, vignetting, gains)
  RigCalibration factory;      // what the recording carries
  RigCalibration truth;        // what the views were rendered through
};

// A camera with realistic sensor defects (noise sigma 2, vignetting 0.3, gains +-5 %) and the
// given lens perturbation seed (0 = lenses as calibrated).
SimCameraSpec RealisticSpec(SimCameraSpec spec, uint64_t perturb_lenses_seed);

StatusOr<LatticeShot> CaptureLatticeShot(const SimCameraSpec& spec, const std::string& scene, uint64_t seed = 1);

}  // namespace px::sim_calib
