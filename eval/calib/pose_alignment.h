// Comparing estimated camera poses with reference poses: a similarity alignment first (SfM
// fixes neither the world frame nor its scale; a refined rig not its common rotation), then
// per-view rotation, camera-centre and focal-length errors.
//
// The alignment's rotation is the mean of the per-view rotation differences (chordal L2 mean);
// scale and translation then follow by least squares on the camera centres (Umeyama's solution
// with that rotation). Orientations fix the rotation well even for a rig a few centimetres
// across, where a centres-only Umeyama would turn the frame by (centre error / rig size)
// radians, a degree for half a millimetre on a 3x3 rig of 25 mm.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "pipeline/core/rig_calibration.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/status.h"

namespace px::eval {

struct Similarity {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  double scale = 1;
  // Maps a point of the estimate's world into the reference's: s R p + t.
  Eigen::Vector3d Apply(const Eigen::Vector3d& p) const { return scale * rotation * p + translation; }
};

struct PoseErrors {
  Similarity alignment;                 // estimate -> reference
  double reference_baseline = 0;        // median distance from each reference camera to its nearest
  std::vector<double> rotation_deg;     // per view, after alignment
  std::vector<double> centre_relative;  // per view: centre distance after alignment / baseline
  std::vector<double> focal_relative;   // per view: |f_est / f_ref - 1| (empty without focals)

  static double Mean(const std::vector<double>& values);
  static double Max(const std::vector<double>& values);
};

// The similarity that best maps the estimated poses onto the reference (as above). Needs two
// or more views with distinct reference centres for scale; with fewer, scale 1.
Similarity AlignPoses(const std::vector<Rigid3>& estimated_cam_from_world,
                      const std::vector<Rigid3>& reference_cam_from_world);

// Aligns and compares; focal lists may be empty (no focal figures) or one per view.
StatusOr<PoseErrors> ComparePoses(const std::vector<Rigid3>& estimated_cam_from_world,
                                  const std::vector<Rigid3>& reference_cam_from_world,
                                  const std::vector<double>& estimated_focal_px = {},
                                  const std::vector<double>& reference_focal_px = {});

// The same for two calibrations of one rig: lens poses (cam_from_rig) and focal lengths (fx).
// Errors when the rigs have different numbers of lenses.
StatusOr<PoseErrors> CompareRigs(const RigCalibration& estimate, const RigCalibration& reference);

}  // namespace px::eval
