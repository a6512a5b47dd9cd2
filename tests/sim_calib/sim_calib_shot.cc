#include "tests/sim_calib/sim_calib_shot.h"

#include "pipeline/core/pixel_format.h"
#include "pipeline/lattice/split_lattice.h"
#include "tests/e2e/e2e_shot.h"

namespace px::sim_calib {

SimCameraSpec RealisticSpec(SimCameraSpec spec, uint64_t perturb_lenses_seed) {
  spec.noise_sigma = 2.0;
  spec.vignetting = 0.3;
  spec.exposure_spread = 0.05;
  spec.perturb_lenses_seed = perturb_lenses_seed;
  return spec;
}

StatusOr<LatticeShot> CaptureLatticeShot(const SimCameraSpec& spec, const std::string& scene, uint64_t seed) {
  PX_ASSIGN_OR_RETURN(e2e::SimulatedShot shot, e2e::CaptureShot(spec, scene, seed));
  PX_ASSIGN_OR_RETURN(cv::Mat sensor, ToBgr(shot.capture.frames.at(0).image));
  LatticeShot result;
  PX_ASSIGN_OR_RETURN(result.tiles, SplitLattice(sensor, shot.rig.lattice));
  result.factory = shot.rig;
  result.truth = shot.truth.rig;
  return result;
}

}  // namespace px::sim_calib
