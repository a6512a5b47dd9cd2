// Triangulation of one point seen by several calibrated views, and the checks that decide
// whether a triangulated point can be trusted.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "pipeline/core/rigid3.h"

namespace px::calib {

// Linear (DLT) triangulation from N >= 2 views: rays[i] is the point's viewing ray in view i's
// camera frame (z > 0), cam_from_world[i] that view's pose. nullopt when the views are fewer
// than two or the rays meet only at infinity (no parallax at all).
std::optional<Eigen::Vector3d> TriangulatePoint(const std::vector<Rigid3>& cam_from_world,
                                                const std::vector<Eigen::Vector3d>& rays);

// The largest angle at the point between two of the views' centres, in degrees: how well the
// point's depth is determined (0 for a point at infinity).
double MaxTriangulationAngleDeg(const Eigen::Vector3d& point_in_world, const std::vector<Rigid3>& cam_from_world);

}  // namespace px::calib
