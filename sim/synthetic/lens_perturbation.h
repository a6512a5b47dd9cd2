// Lenses that are not where the factory calibration says: cheap plastic lenses shift with
// temperature and knocks. The simulator renders through the perturbed ("true") lenses while the
// recording carries the factory calibration, so per-shot refinement has something real to
// recover, and the truth stays in the ground truth for evaluation.
#pragma once

#include <cstdint>

#include "pipeline/core/rig_calibration.h"
#include "pipeline/core/status.h"

namespace px {

// Each quantity is drawn uniformly in [-magnitude, +magnitude], independently per lens.
struct LensPerturbation {
  double focal_relative = 0.01;     // fx and fy scaled together by 1 + u, [0, 0.2]
  double principal_point_px = 2.0;  // cx and cy shifted by u pixels each, [0, 50]
  double rotation_deg = 0.3;        // rotation about each of the lens's x, y, z axes, [0, 10]
  double centre_m = 0.0005;         // centre moved along each rig axis, metres, [0, 0.05]

  Status Validate() const;
};

// The true rig: `factory` with every lens perturbed by draws from `seed` (the same seed always
// gives the same lenses). Distortion, lattice and depth range are unchanged.
RigCalibration PerturbLenses(const RigCalibration& factory, const LensPerturbation& magnitudes, uint64_t seed);

}  // namespace px
