// Hand-held mode: incremental structure from motion for 2 to ~20 photos with unknown poses
// (a tethered camera or files). Features and all-pairs matching verified by a fundamental matrix;
// the initial pair chosen by matches and parallax, not by a wide baseline (the paper's inputs
// are 3-4 inches apart, where COLMAP finds "no good initial image pair"); the rest registered by
// P3P RANSAC, with triangulation and bundle adjustment after each; focal length from metadata
// when given, else self-calibrated (a sweep scored by two-view adjustment, then refined). A set
// whose views show no parallax (a pure rotation) fails with a message saying so.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "pipeline/calib/sfm_options.h"
#include "pipeline/core/camera_model.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/status.h"

namespace px::calib {

struct SfmImage {
  cv::Mat image;  // 8-bit BGR or grey, any size
  // Intrinsics from metadata (EXIF focal length, a calibration) for this image's size; fx == 0
  // means unknown: self-calibrated, principal point at the centre, no distortion.
  CameraModel intrinsics;
  // Images of one camera (same body and zoom) share self-calibrated intrinsics.
  int camera_id = 0;
};

struct SfmView {
  bool registered = false;
  std::string note;       // why not registered ("" when registered)
  CameraModel camera;     // refined intrinsics, for the input image's size
  Rigid3 cam_from_world;  // world: the first registered image's camera, scaled (see options)
  int features = 0;
  int observations = 0;   // of points in the final reconstruction
  double depth_near = 0;  // 2nd and 98th percentile depth of its points (scene units)
  double depth_far = 0;
};

struct SfmPair {
  int image_a = -1;
  int image_b = -1;
  int matches = 0;   // ratio + mutual tests
  int verified = 0;  // fundamental-matrix inliers
};

struct SfmReport {
  bool success = false;
  std::string failure;                // why no reconstruction ("" on success)
  std::vector<std::string> warnings;  // degraded parts (unregistered images, weak focal, planar)
  int num_images = 0;
  int num_registered = 0;
  int num_points = 0;
  int num_observations = 0;
  double rms_px = 0;  // final reprojection RMS, input-image pixels
  int initial_image_a = -1;
  int initial_image_b = -1;
  double initial_parallax_px = 0;       // rotation-compensated, median, of the initial pair
  double initial_parallax_ratio = 0;    // the same over the pair's epipolar noise
  double initial_homography_ratio = 0;  // its homography residual over its noise (~1.3 planar)
  std::string focal_source;             // "metadata", "self-calibrated", or a mix
  // Largest rotation between two registered views, degrees. A self-calibrated focal length
  // needs rotation: views that are only translated (a grid of parallel cameras) see the same
  // images for any focal length with the depths rescaled, so it is then flagged unobservable.
  double max_view_rotation_deg = 0;
  bool focal_observable = true;                        // false: self-calibrated and max_view_rotation_deg too small
  std::vector<std::pair<double, double>> focal_sweep;  // (focal px, two-view RMS px) when swept
  std::vector<SfmPair> pairs;
  double features_ms = 0;
  double matching_ms = 0;
  double reconstruction_ms = 0;
  double total_ms = 0;
};

struct SfmResult {
  std::vector<SfmView> views;           // one per input image
  std::vector<Eigen::Vector3d> points;  // world frame
  SfmReport report;
};

// Errors only for invalid options or unusable input (no images, an empty or non-8-bit image);
// a set that cannot be reconstructed returns report.success == false with the reason.
StatusOr<SfmResult> RunIncrementalSfm(const std::vector<SfmImage>& images, const SfmOptions& options);

}  // namespace px::calib
