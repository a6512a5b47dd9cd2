// Robust relative pose between two calibrated views (OpenGV: five-point (Stewenius) or
// eight-point RANSAC, then nonlinear refinement on the inliers), with the figures that tell a
// usable pair from a degenerate one: how much parallax is left once the rotation is removed,
// how many matches a pure rotation explains, and how many a single homography (a plane) does.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "pipeline/calib/ransac_options.h"
#include "pipeline/core/rigid3.h"

namespace px::calib {

enum class RelativePoseSolver {
  kFivePoint,   // minimal, works for planar scenes too
  kEightPoint,  // linear; needs a general 3D scene
};

struct RelativePoseResult {
  bool success = false;
  std::string failure;       // why not, when !success
  Rigid3 b_from_a;           // translation of unit length: two views fix no scale
  std::vector<int> inliers;  // indices into the correspondences
  int num_correspondences = 0;
  // Inliers of the best rotation-only model (twice the angle threshold: generous to rotation).
  int rotation_only_inliers = 0;
  // Median over the inliers of the angle between b's ray and a's ray turned by the best pure
  // rotation, in pixels at the focal length: the parallax that reveals depth (~noise for a
  // pure rotation; for a plane or a distant scene, only its depth's share of the motion).
  double median_parallax_px = 0;
  // Median Sampson (first-order epipolar) distance of the inliers, in pixels at the focal
  // length: the matches' own noise. For pure noise the parallax above is about 1.75 times it
  // (a 2D residual against a 1D one), so a ratio well above 2 means real parallax.
  double median_epipolar_error_px = 0;
  // Fraction of the inliers that one homography also explains within 5 times the epipolar
  // noise below: close to 1 when the scene is a plane, at infinity, or too far for the baseline.
  double homography_inlier_fraction = 0;
  // 90th percentiles of the inliers' transfer error under that homography and of their
  // Sampson error, pixels at the focal length. A high percentile, because a wall behind the
  // objects can hold most matches: the objects' parallax shows in the tail. Their ratio is
  // ~1.3 for pure noise; under about 3 only a plane (or a scene at infinity) is seen, and the
  // translation's direction and the lens positions are not observable.
  double p90_homography_error_px = 0;
  double p90_epipolar_error_px = 0;

  // median_parallax_px / median_epipolar_error_px and p90 homography / p90 epipolar error
  // (0 when the noise is 0).
  double ParallaxRatio() const;
  double HomographyRatio() const;
};

// rays_a[i] and rays_b[i] are the same point's viewing rays (any positive length, z > 0 for the
// homography check) in each camera's frame. Needs at least 8 correspondences.
RelativePoseResult EstimateRelativePose(const std::vector<Eigen::Vector3d>& rays_a,
                                        const std::vector<Eigen::Vector3d>& rays_b,
                                        RelativePoseSolver solver,
                                        const RansacOptions& options);

}  // namespace px::calib
