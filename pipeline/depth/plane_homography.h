// Geometry of the plane sweep: which views to match against, and the homography a
// fronto-parallel plane in the reference camera induces between two views.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "pipeline/core/camera_model.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/view.h"

namespace px::depth {

// Maps reference pixels to source pixels (homogeneous, x_src ~ H x_ref) for the plane z = depth_m
// in the reference camera. With src_from_ref = (R, t) and n = (0, 0, 1), a point X on the plane has
// n.X / depth_m = 1, so X_src = R X + t = (R + t n^T / depth_m) X and
//   H = K_src (R + t n^T / depth_m) K_ref^-1.
// (The textbook "R - t n^T / d" writes the plane as n.X + d = 0.) Both cameras must be pinhole
// (undistorted); their pixel grids are whatever `ref` and `src` describe (e.g. working scale).
Eigen::Matrix3d PlaneHomography(const CameraModel& ref,
                                const Rigid3& ref_from_world,
                                const CameraModel& src,
                                const Rigid3& src_from_world,
                                double depth_m);

// Maps a reference pixel (x, y) at inverse depth u (1/m, any surface) into a source view:
// x_src ~ a (x, y, 1) + b u, from X_src = R K_ref^-1 (x, y, 1) / u + t scaled by u.
struct InverseDepthMapping {
  Eigen::Matrix3d a;
  Eigen::Vector3d b;
  // False where the point lies behind the source camera.
  bool Map(double x, double y, double u, double* sx, double* sy) const {
    double u_src;
    return Map(x, y, u, sx, sy, &u_src);
  }
  // The same, with the point's inverse depth in the source camera (q's z is u z_src).
  bool Map(double x, double y, double u, double* sx, double* sy, double* u_src) const {
    const Eigen::Vector3d q = a * Eigen::Vector3d(x, y, 1.0) + b * u;
    if (!(q.z() > 1e-12)) return false;
    *sx = q.x() / q.z();
    *sy = q.y() / q.z();
    *u_src = u / q.z();
    return true;
  }
};
InverseDepthMapping MappingInto(const CameraModel& ref,
                                const Rigid3& ref_from_world,
                                const CameraModel& src,
                                const Rigid3& src_from_world);

// Indices of up to `count` other views nearest to views[reference] by camera-centre distance,
// nearest first (ties by index). Views at the same centre are skipped: they see no parallax.
std::vector<int> NearestNeighbourViews(const std::vector<View>& views, int reference, int count);

}  // namespace px::depth
