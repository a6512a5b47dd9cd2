// Options of per-shot refinement of a lattice camera's rig calibration (rig_refinement.h).
#pragma once

#include <cstdint>

#include "pipeline/calib/features.h"
#include "pipeline/calib/matching.h"
#include "pipeline/calib/ransac_options.h"
#include "pipeline/core/status.h"

namespace px::calib {

// SIFT with fewer keypoints than the default: tiles are small and neighbours share most of them.
// Found on tiles reduced to 1024 px at most: a 12 MP sensor's 1330x1000 tiles then cost half the
// detection, and a keypoint's error (a few tenths of a reduced pixel) stays below what depth
// matching at half a tile's resolution resolves.
inline FeatureOptions RigFeatures() {
  FeatureOptions features;
  features.max_features = 1200;
  features.max_image_dim_px = 1024;
  return features;
}

struct RigRefinementOptions {
  // false: the factory calibration is used as it is (no features, no matching).
  bool enabled = true;
  FeatureOptions features = RigFeatures();  // SIFT, 1200 per view
  MatchOptions matching;                    // ratio 0.8, mutual
  // A match must lie within this distance of the epipolar segment that the factory calibration
  // predicts (points from half the rig's nominal minimum depth to infinity), pixels, [1, 200].
  // Covers lenses that moved: 0.3 deg and 1 % of focal length move points by a few pixels.
  double epipolar_tolerance_px = 12.0;
  // Lens pairs are matched when their centres are at most this many times the smallest lens
  // spacing apart, [1, 100]: 1.5 takes neighbours and diagonals.
  double max_pair_distance_spacings = 1.5;
  RansacOptions ransac;  // five-point RANSAC per pair and P3P per view; focal_px is set from the rig

  // Bundle adjustment priors: how far a lens may plausibly have moved since the factory
  // (standard deviations). Rotation in degrees (0, 10], centre in lens spacings (0, 1], focal
  // length relative (0, 0.5], principal point in pixels (0, 100].
  double rotation_sigma_deg = 1.0;
  double centre_sigma_spacings = 0.04;
  double focal_sigma_relative = 0.02;
  double principal_point_sigma_px = 5.0;
  bool refine_principal_point = true;
  bool refine_radial_distortion = false;  // k1, k2: weakly observable from one shot
  // Cauchy loss scale (0, 100] and the error above which an observation is dropped after the
  // first adjustment (0, 100], pixels.
  double loss_scale_px = 1.0;
  double outlier_error_px = 3.0;

  // At most this many tracks enter the adjustment, the longest first, spread over the image,
  // [50, 100000]: a thousand well-spread points fix nine lenses; more only cost time.
  int max_tracks = 1200;

  // When refinement is trusted. A view with fewer observations keeps its factory calibration;
  // with fewer than two such views, or fewer tracks in all, the whole shot does, [1, 100000].
  int min_observations_per_view = 40;
  int min_tracks = 100;
  // A change beyond these is not a lens that moved but a failure (e.g. wrong matches): the
  // shot keeps the factory calibration. Degrees (0, 90], spacings (0, 10], relative (0, 1].
  double max_rotation_change_deg = 2.0;
  double max_centre_change_spacings = 0.25;
  double max_focal_change_relative = 0.05;
  // When the median lens pair's matches leave, after the best homography, residuals (90th
  // percentile) under this many times their epipolar noise, the scene is a plane or too far for the
  // baseline (pure noise gives ~1.3): lens centres are then held at the factory's, [1, 100].
  double planar_homography_ratio = 3.0;
  // The refined calibration is used only when it lowers the reprojection RMS by at least this
  // many pixels, [0, 10]: below, the lenses have not measurably moved and the factory's stand.
  double min_rms_gain_px = 0.05;
  // The factory calibration is kept without any adjustment when it explains the matches to
  // within this RMS (pixels at the features' scale, [0, 10]; 0 = always adjust): about what
  // SIFT keypoints on reduced tiles resolve, so an adjustment could only fit their noise.
  double factory_fits_rms_px = 0.4;

  uint64_t seed = 1;    // RANSAC sampling: the same seed and shot give the same calibration
  int num_threads = 1;  // Ceres threads [1, 64]; features and pairs use OpenCV's pool

  Status Validate() const;
};

}  // namespace px::calib
