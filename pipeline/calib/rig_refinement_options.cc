#include "pipeline/calib/rig_refinement_options.h"

#include <string>

#include "pipeline/core/option_range.h"

namespace px::calib {

namespace {

bool InOpenClosed(double value, double low, double high) { return value > low && value <= high; }

}  // namespace

Status RigRefinementOptions::Validate() const {
  PX_RETURN_IF_ERROR(features.Validate().WithContext("rig refinement options"));
  PX_RETURN_IF_ERROR(matching.Validate().WithContext("rig refinement options"));
  PX_RETURN_IF_ERROR(ransac.Validate().WithContext("rig refinement options"));
  if (!(epipolar_tolerance_px >= 1 && epipolar_tolerance_px <= 200)) {
    return OptionOutOfRange("rig refinement options", "epipolar_tolerance_px", epipolar_tolerance_px, "[1, 200]");
  }
  if (!(max_pair_distance_spacings >= 1 && max_pair_distance_spacings <= 100)) {
    return OptionOutOfRange(
        "rig refinement options", "max_pair_distance_spacings", max_pair_distance_spacings, "[1, 100]");
  }
  if (!InOpenClosed(rotation_sigma_deg, 0, 10))
    return OptionOutOfRange("rig refinement options", "rotation_sigma_deg", rotation_sigma_deg, "(0, 10]");
  if (!InOpenClosed(centre_sigma_spacings, 0, 1)) {
    return OptionOutOfRange("rig refinement options", "centre_sigma_spacings", centre_sigma_spacings, "(0, 1]");
  }
  if (!InOpenClosed(focal_sigma_relative, 0, 0.5)) {
    return OptionOutOfRange("rig refinement options", "focal_sigma_relative", focal_sigma_relative, "(0, 0.5]");
  }
  if (!InOpenClosed(principal_point_sigma_px, 0, 100)) {
    return OptionOutOfRange("rig refinement options", "principal_point_sigma_px", principal_point_sigma_px, "(0, 100]");
  }
  if (!InOpenClosed(loss_scale_px, 0, 100))
    return OptionOutOfRange("rig refinement options", "loss_scale_px", loss_scale_px, "(0, 100]");
  if (!InOpenClosed(outlier_error_px, 0, 100))
    return OptionOutOfRange("rig refinement options", "outlier_error_px", outlier_error_px, "(0, 100]");
  if (min_observations_per_view < 1 || min_observations_per_view > 100000) {
    return OptionOutOfRange(
        "rig refinement options", "min_observations_per_view", min_observations_per_view, "[1, 100000]");
  }
  if (max_tracks < 50 || max_tracks > 100000)
    return OptionOutOfRange("rig refinement options", "max_tracks", max_tracks, "[50, 100000]");
  if (min_tracks < 1 || min_tracks > 100000)
    return OptionOutOfRange("rig refinement options", "min_tracks", min_tracks, "[1, 100000]");
  if (!InOpenClosed(max_rotation_change_deg, 0, 90)) {
    return OptionOutOfRange("rig refinement options", "max_rotation_change_deg", max_rotation_change_deg, "(0, 90]");
  }
  if (!InOpenClosed(max_centre_change_spacings, 0, 10)) {
    return OptionOutOfRange(
        "rig refinement options", "max_centre_change_spacings", max_centre_change_spacings, "(0, 10]");
  }
  if (!InOpenClosed(max_focal_change_relative, 0, 1)) {
    return OptionOutOfRange("rig refinement options", "max_focal_change_relative", max_focal_change_relative, "(0, 1]");
  }
  if (!(planar_homography_ratio >= 1 && planar_homography_ratio <= 100)) {
    return OptionOutOfRange("rig refinement options", "planar_homography_ratio", planar_homography_ratio, "[1, 100]");
  }
  if (!(min_rms_gain_px >= 0 && min_rms_gain_px <= 10))
    return OptionOutOfRange("rig refinement options", "min_rms_gain_px", min_rms_gain_px, "[0, 10]");
  if (!(factory_fits_rms_px >= 0 && factory_fits_rms_px <= 10))
    return OptionOutOfRange("rig refinement options", "factory_fits_rms_px", factory_fits_rms_px, "[0, 10]");
  if (num_threads < 1 || num_threads > 64)
    return OptionOutOfRange("rig refinement options", "num_threads", num_threads, "[1, 64]");
  return OkStatus();
}

}  // namespace px::calib
