#include "sim/synthetic/sim_camera.h"

#include <cmath>
#include <sstream>

namespace px {
namespace {

Status Invalid(const std::string& field, const std::string& problem) {
  return InvalidArgumentError("sim camera spec: " + field + " " + problem);
}

template <typename T>
std::string Str(T value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

}  // namespace

SimCameraSpec SimCameraSpec::Pop9() { return SimCameraSpec(); }

SimCameraSpec SimCameraSpec::Integral5x4() {
  SimCameraSpec spec;
  spec.name = "sim-integral5x4";
  spec.rows = 4;
  spec.cols = 5;
  spec.tile_width = 320;
  spec.tile_height = 240;
  spec.baseline_m = 0.012;
  spec.focal_px = 280.0;
  return spec;
}

Status SimCameraSpec::Validate() const {
  if (name.empty()) return Invalid("name", "is empty");
  if (rows < 1 || cols < 1) return Invalid("rows x cols", Str(rows) + "x" + Str(cols) + " has no lenses");
  if (tile_width < 8 || tile_height < 8) {
    return Invalid("tile_width x tile_height", Str(tile_width) + "x" + Str(tile_height) + " is below 8x8");
  }
  if (gap_px < 0) return Invalid("gap_px", Str(gap_px) + " is negative");
  if (!(baseline_m > 0) || !std::isfinite(baseline_m))
    return Invalid("baseline_m", Str(baseline_m) + " is not positive");
  if (!(focal_px > 0) || !std::isfinite(focal_px)) return Invalid("focal_px", Str(focal_px) + " is not positive");
  for (size_t i = 0; i < distortion.size(); ++i) {
    if (!std::isfinite(distortion[i])) return Invalid("distortion[" + Str(i) + "]", "is not finite");
  }
  if (!(vignetting >= 0 && vignetting < 1)) return Invalid("vignetting", Str(vignetting) + " is not in [0, 1)");
  if (!(exposure_spread >= 0 && exposure_spread < 1)) {
    return Invalid("exposure_spread", Str(exposure_spread) + " is not in [0, 1)");
  }
  if (!(noise_sigma >= 0 && noise_sigma <= 64)) return Invalid("noise_sigma", Str(noise_sigma) + " is not in [0, 64]");
  if (supersampling < 1 || supersampling > 8) return Invalid("supersampling", Str(supersampling) + " is not in [1, 8]");
  if (gap_level < 0 || gap_level > 255) return Invalid("gap_level", Str(gap_level) + " is not in [0, 255]");
  if (!(gap_noise_sigma >= 0 && gap_noise_sigma <= 64)) {
    return Invalid("gap_noise_sigma", Str(gap_noise_sigma) + " is not in [0, 64]");
  }
  if (!(depth_min_m > 0 && depth_max_m > depth_min_m)) {
    return Invalid("depth range",
                   "[" + Str(depth_min_m) + ", " + Str(depth_max_m) + "] m is not positive and increasing");
  }
  PX_RETURN_IF_ERROR(perturbation.Validate().WithContext("sim camera spec"));
  const LatticeLayout layout = Layout();
  StatusOr<size_t> bytes = PackedImageBytes(pixel_format, layout.sensor_width, layout.sensor_height);
  if (!bytes.ok()) return bytes.status().WithContext("sim camera spec: pixel_format");
  return Calibration().Validate().WithContext("sim camera spec");
}

LatticeLayout SimCameraSpec::Layout() const {
  return LatticeLayout::Regular(rows, cols, tile_width, tile_height, gap_px, orientation);
}

RigCalibration SimCameraSpec::Calibration() const {
  RigCalibration rig;
  rig.rig_name = name;
  rig.lattice = Layout();
  rig.nominal_depth_min_m = depth_min_m;
  rig.nominal_depth_max_m = depth_max_m;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      LensCalibration lens;
      lens.camera = CameraModel::Pinhole(tile_width, tile_height, focal_px);
      lens.camera.distortion = distortion;
      const Eigen::Vector3d centre_in_rig((c - (cols - 1) * 0.5) * baseline_m, (r - (rows - 1) * 0.5) * baseline_m, 0);
      // Axes parallel to the rig's: cam_from_rig only moves the origin to the lens centre.
      lens.cam_from_rig = Rigid3(Eigen::Quaterniond::Identity(), -centre_in_rig);
      rig.lenses.push_back(lens);
    }
  }
  return rig;
}

RigCalibration SimCameraSpec::TrueCalibration() const {
  if (perturb_lenses_seed == 0) return Calibration();
  return PerturbLenses(Calibration(), perturbation, perturb_lenses_seed);
}

}  // namespace px
