// Robust absolute pose of a calibrated view from 2D-3D correspondences (OpenGV: P3P (Kneip)
// or EPnP in RANSAC, then nonlinear refinement on the inliers).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "pipeline/calib/ransac_options.h"
#include "pipeline/core/rigid3.h"

namespace px::calib {

enum class AbsolutePoseSolver {
  kP3p,   // Kneip's P3P: minimal, the usual RANSAC kernel
  kEpnp,  // EPnP on 6 points per hypothesis
};

struct AbsolutePoseResult {
  bool success = false;
  std::string failure;  // why not, when !success
  Rigid3 cam_from_world;
  std::vector<int> inliers;  // indices into the correspondences
};

// rays[i] (camera frame, any positive length) sees points_in_world[i]. Needs at least 6.
AbsolutePoseResult EstimateAbsolutePose(const std::vector<Eigen::Vector3d>& rays,
                                        const std::vector<Eigen::Vector3d>& points_in_world,
                                        AbsolutePoseSolver solver,
                                        const RansacOptions& options);

}  // namespace px::calib
