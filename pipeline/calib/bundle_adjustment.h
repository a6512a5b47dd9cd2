// Bundle adjustment (Ceres): camera poses, intrinsics and 3D points refined together to
// minimise reprojection error, with optional priors that keep each camera near a reference (the
// factory calibration of a rig). Poses are parametrised by rotation and camera centre, so a
// centre can be held while the rotation moves (used when the scene cannot fix translations).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "pipeline/core/camera_model.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/status.h"

namespace px::calib {

struct BaCamera {
  CameraModel camera;  // intrinsics (with distortion) of the observed (distorted) pixels
  Rigid3 cam_from_world;
  // Cameras with the same group >= 0 share one set of intrinsics (one camera body, e.g. a
  // hand-held phone); -1 = this camera's own. Shared cameras must start with equal intrinsics.
  int intrinsics_group = -1;
  bool pose_fixed = false;  // hold this camera's rotation and centre (e.g. the gauge of an SfM)
};

struct BaObservation {
  int camera = -1;
  int point = -1;
  Eigen::Vector2d pixel;  // observed, distorted pixel coordinates
};

struct BaProblem {
  std::vector<BaCamera> cameras;
  std::vector<Eigen::Vector3d> points;  // world frame
  std::vector<BaObservation> observations;
};

// Keeps one camera near a reference: rotation and centre, focal length and principal point,
// each with its standard deviation (a Gaussian prior, weighted against pixel residuals of
// sigma 1 px). Zero or negative sigma = no prior on that quantity.
struct BaPrior {
  int camera = -1;
  Rigid3 cam_from_world;
  double rotation_sigma_deg = 0;
  double centre_sigma_m = 0;
  double focal_px = 0;
  double focal_sigma_relative = 0;  // e.g. 0.02 = 2 %
  double cx = 0, cy = 0;
  double principal_point_sigma_px = 0;
};

struct BundleAdjustmentOptions {
  bool refine_poses = true;    // rotations and centres of cameras not pose_fixed
  bool refine_centres = true;  // false: centres held (rotations still move)
  bool refine_focal = true;    // one focal per intrinsics block; fy / fx is kept
  bool refine_principal_point = false;
  bool refine_radial = false;  // k1 and k2
  bool refine_points = true;
  // Cauchy loss scale in pixels, (0, 100]: residuals well above it count little (outliers).
  double loss_scale_px = 2.0;
  int max_iterations = 100;  // [1, 1000]
  // Stop when an iteration lowers the cost by less than this fraction, (0, 1).
  double function_tolerance = 1e-6;
  int num_threads = 1;  // [1, 64]
  // Keeps the distance between two camera centres fixed (the gauge of an SfM's scale):
  // indices of the two cameras, or -1 for none.
  int scale_anchor_a = -1;
  int scale_anchor_b = -1;

  Status Validate() const;
};

struct BundleAdjustmentReport {
  bool converged = false;  // Ceres reported convergence (or no change was needed)
  std::string message;     // Ceres's termination message
  int iterations = 0;
  int num_observations = 0;
  double initial_rms_px = 0;  // reprojection error (2D, per observation) before and after
  double final_rms_px = 0;
  double ms = 0;
};

// Refines `problem` in place. Observations naming a missing camera or point are an error, as is
// a shared intrinsics group whose cameras start with different intrinsics.
StatusOr<BundleAdjustmentReport> BundleAdjust(BaProblem* problem,
                                              const std::vector<BaPrior>& priors,
                                              const BundleAdjustmentOptions& options);

// Reprojection error (pixels, 2D norm) of each observation; +inf when the point is behind the
// camera.
std::vector<double> ReprojectionErrors(const BaProblem& problem);
// Root mean square of ReprojectionErrors over the observations in front of their camera.
double ReprojectionRms(const BaProblem& problem);

}  // namespace px::calib
