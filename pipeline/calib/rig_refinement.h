// Per-shot refinement of a lattice camera's calibration. Cheap plastic lenses move a little with
// temperature and knocks, so each shot re-estimates every lens from the shot itself: features
// per view, matches between nearby lenses guided by the factory calibration's epipolar geometry,
// five-point RANSAC per pair, tracks, triangulation, P3P per view, then bundle adjustment of
// poses, focal lengths, principal points and points with the factory calibration as a prior.
// When the result cannot be trusted the factory calibration is kept and the report says why.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "pipeline/calib/rig_refinement_options.h"
#include "pipeline/core/rig_calibration.h"
#include "pipeline/core/status.h"

namespace px::calib {

// What happened to one lens.
struct ViewRefinement {
  int view = -1;
  int features = 0;
  int observations = 0;  // track observations in the final adjustment
  bool refined = false;  // false: this lens keeps its factory calibration (see `note`)
  std::string note;      // why a lens was held, or "" when refined
  // Refined minus factory (zero when not refined).
  double rotation_change_deg = 0;
  double centre_change_m = 0;
  double focal_change_relative = 0;
  double principal_point_change_px = 0;
};

// Figures of one matched lens pair.
struct PairRefinement {
  int view_a = -1;
  int view_b = -1;
  int matches = 0;  // after the ratio and mutual tests within the epipolar band
  int inliers = 0;  // of the five-point RANSAC
  double median_parallax_px = 0;
  double median_epipolar_error_px = 0;
  double homography_fraction = 0;
  double homography_ratio = 0;  // median homography residual over the epipolar noise
};

struct RigRefinementReport {
  bool refined = false;         // the refined calibration is used
  std::string fallback_reason;  // why the factory calibration was kept ("" when refined)
  // The factory calibration was kept because it fits the shot as well as a refined one would: its
  // RMS within RigRefinementOptions::factory_fits_rms_px (not adjusted at all), or an adjustment's
  // gain under min_rms_gain_px with the factory RMS at most 1 px. No degradation.
  bool factory_fits = false;
  std::vector<std::string> warnings;  // degraded parts (held lenses, held centres)
  int num_pairs = 0;                  // lens pairs matched
  int num_matches = 0;                // summed over pairs
  int num_inliers = 0;                // summed over pairs
  int num_tracks = 0;                 // points in the final adjustment
  int num_observations = 0;
  // Reprojection RMS (pixels) of the same observations with the points re-triangulated: with
  // the factory calibration, and after refinement.
  double rms_before_px = 0;
  double rms_after_px = 0;
  bool centres_held = false;           // the scene could not fix lens positions (planar or too far)
  double median_homography_ratio = 0;  // over the pairs: ~1.3 for a plane, more with depth
  double max_rotation_change_deg = 0;
  double max_centre_change_m = 0;
  double max_focal_change_relative = 0;
  std::vector<ViewRefinement> views;
  std::vector<PairRefinement> pairs;
  double features_ms = 0;
  double matching_ms = 0;  // matching, RANSAC, tracks, triangulation, P3P
  double adjustment_ms = 0;
  int adjustment_iterations = 0;  // summed over the adjustments run
  double total_ms = 0;
};

struct RigRefinementResult {
  RigCalibration rig;  // refined, or the factory calibration (report.fallback_reason)
  RigRefinementReport report;
};

// upright_tiles[i] was taken by factory.lenses[i] (distorted as the lens distorts; sizes as its
// intrinsics). Errors only for input that contradicts itself (an invalid rig, a tile count or
// size that differs from the rig, invalid options); everything the shot itself cannot support
// (blank views, too few matches, different scenes, degenerate geometry) is a fallback in the
// report, never an error.
StatusOr<RigRefinementResult> RefineRigCalibration(const std::vector<cv::Mat>& upright_tiles,
                                                   const RigCalibration& factory,
                                                   const RigRefinementOptions& options);

}  // namespace px::calib
