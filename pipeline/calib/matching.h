// Descriptor matching between two views' features: Lowe's ratio test and a mutual
// (cross-check) test, either against every feature (hand-held sets, unknown geometry) or only
// against candidates that the factory calibration allows (a rig: near the epipolar segment).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "pipeline/calib/features.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/status.h"

namespace px::calib {

struct MatchOptions {
  // Lowe's ratio: keep a match when best distance < ratio * second best, (0, 1].
  double ratio = 0.8;
  // Keep a match only when each feature is the other's best match.
  bool mutual = true;

  Status Validate() const;
};

struct FeatureMatch {
  int a = -1;  // feature index in view a
  int b = -1;  // feature index in view b
};

// Every feature of `a` against every feature of `b` (brute force; SIFT: L2, ORB: Hamming).
// Both must use the same descriptor type; an empty side gives no matches.
std::vector<FeatureMatch> MatchAll(const Features& a, const Features& b, const MatchOptions& options);

// Only the listed candidates: candidates_of_a[i] holds the features of `b` that feature i of `a`
// may match. The ratio test compares the best and second best candidate of each feature of `a`
// (one candidate passes when it is the only one); the mutual test uses the same candidate sets.
std::vector<FeatureMatch> MatchCandidates(const Features& a,
                                          const Features& b,
                                          const std::vector<std::vector<int>>& candidates_of_a,
                                          const MatchOptions& options);

// Where the factory calibration says a feature may reappear: for each normalised image point of
// view a (x, y, 1 on the z = 1 plane), the points of view b (undistorted pixels) within
// `tolerance_px` of the epipolar segment that a point at depth [min_depth, +inf) along a's ray
// projects to. `b_from_a` and `k_b` (pinhole) come from the calibration. Grid-indexed: cost grows
// with the candidates, not with the product of the feature counts.
std::vector<std::vector<int>> EpipolarCandidates(const std::vector<Eigen::Vector3d>& rays_a,
                                                 const std::vector<Eigen::Vector2d>& undistorted_px_b,
                                                 const Rigid3& b_from_a,
                                                 const Eigen::Matrix3d& k_b,
                                                 double min_depth,
                                                 double tolerance_px);

}  // namespace px::calib
