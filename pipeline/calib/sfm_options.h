// Options of hand-held structure from motion (incremental_sfm.h).
#pragma once

#include <cstdint>

#include "pipeline/calib/features.h"
#include "pipeline/calib/matching.h"
#include "pipeline/calib/ransac_options.h"
#include "pipeline/core/status.h"

namespace px::calib {

// SIFT with more keypoints than a rig tile needs: hand-held photos are larger and overlap less.
inline FeatureOptions SfmFeatures() {
  FeatureOptions features;
  features.max_features = 4000;
  features.max_image_dim_px = 1600;
  return features;
}

struct SfmOptions {
  FeatureOptions features = SfmFeatures();
  MatchOptions matching;  // ratio 0.8, mutual
  // Geometric verification and registration thresholds, pixels of the feature image, (0, 50]:
  // matches farther than this from their epipolar line (fundamental matrix) are dropped, and
  // so are 2D-3D correspondences in P3P.
  double max_error_px = 3.0;
  RansacOptions ransac;  // five-point and P3P RANSAC: iterations, confidence, seed (its
                         // max_error_px and focal_px are set per image from the above)
  // A pair is used when it has this many verified matches, [8, 100000].
  int min_pair_matches = 30;
  // A pair shows depth when its rotation-compensated parallax is at least this many times its
  // epipolar noise (pure noise gives ~1.75), [1, 100]. Without one such pair the set is a pure
  // rotation (or too far for its baseline) and fails.
  double min_parallax_ratio = 3.0;
  // The initial pair: among pairs with enough parallax, the most matches weighted by parallax
  // up to this many pixels (more parallax fixes depth better; beyond it, matches count), (0, 1000].
  double target_parallax_px = 20.0;
  // A view is registered when P3P finds this many inliers, [6, 100000].
  int min_registration_inliers = 15;

  // Focal length. Images with a focal length from metadata (EXIF or a rig calibration) use it,
  // refined within `metadata_focal_sigma_relative` (0, 1]; without, it is self-calibrated: a
  // sweep over [min, max] x the larger image side (0.2 <= min < max <= 10) in `focal_sweep_steps`
  // steps [3, 100], scored by the initial pair's two-view adjustment, then refined with every view.
  double metadata_focal_sigma_relative = 0.05;
  double focal_sweep_min = 0.5;
  double focal_sweep_max = 2.5;
  int focal_sweep_steps = 15;
  // Below this rotation between any two registered views, degrees [0, 45], the focal length is
  // unobservable: a self-calibrated one is reported so (a warning, report.focal_observable), and
  // focal lengths from metadata are held rather than refined.
  double min_rotation_for_focal_deg = 1.0;
  // When no two registered views are turned by this much, degrees [0, 45] (0 = never), but
  // some by 0.25 degree or more, the set is rebuilt from the initial pair's translation-only
  // pose and the better fit kept: parallel cameras with little parallax let the five-point pose
  // start in the wrong basin.
  double parallel_restart_max_rotation_deg = 5.0;
  bool refine_radial_distortion = false;  // k1, k2 in the final adjustment

  double loss_scale_px = 2.0;     // Cauchy loss scale, (0, 100]
  double outlier_error_px = 4.0;  // observations above are dropped after each adjustment, (0, 100]
  // Scale of the result: the median depth of the points in their views, (0, 1e6] (scene units;
  // metres when the real scale is unknown is a guess, see the report).
  double median_depth = 1.0;
  int num_threads = 1;  // Ceres threads [1, 64]; features and matching use OpenCV's pool

  Status Validate() const;
};

}  // namespace px::calib
