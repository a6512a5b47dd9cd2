// The rig calibration: per-lens intrinsics and poses of a multi-lens camera, written at the
// factory and refined per shot. Serialised as versioned JSON (rig_calibration_json.h).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "pipeline/core/camera_model.h"
#include "pipeline/core/lattice_layout.h"
#include "pipeline/core/rigid3.h"

namespace px {

struct LensCalibration {
  CameraModel camera;   // intrinsics of the upright tile image, in tile pixels
  Rigid3 cam_from_rig;  // rig frame: centred on the lattice, x right, y down, z forward
};

struct RigCalibration {
  static constexpr int kSchemaVersion = 1;

  std::string rig_name;                 // e.g. "sim-pop9"
  LatticeLayout lattice;                // empty (rows == 0) for image sets
  std::vector<LensCalibration> lenses;  // one per tile / view, same order
  double nominal_depth_min_m = 0.3;     // scene depth range the rig is designed for
  double nominal_depth_max_m = 10.0;

  int NumViews() const { return static_cast<int>(lenses.size()); }
  // Every lens valid, count matching the lattice, tile sizes matching the intrinsics, depth range sane.
  Status Validate() const;
};

}  // namespace px
