#include "pipeline/calib/sfm_options.h"

#include <string>

#include "pipeline/core/option_range.h"

namespace px::calib {

Status SfmOptions::Validate() const {
  PX_RETURN_IF_ERROR(features.Validate().WithContext("sfm options"));
  PX_RETURN_IF_ERROR(matching.Validate().WithContext("sfm options"));
  PX_RETURN_IF_ERROR(ransac.Validate().WithContext("sfm options"));
  if (!(max_error_px > 0 && max_error_px <= 50))
    return OptionOutOfRange("sfm options", "max_error_px", max_error_px, "(0, 50]");
  if (min_pair_matches < 8 || min_pair_matches > 100000) {
    return OptionOutOfRange("sfm options", "min_pair_matches", min_pair_matches, "[8, 100000]");
  }
  if (!(min_parallax_ratio >= 1 && min_parallax_ratio <= 100)) {
    return OptionOutOfRange("sfm options", "min_parallax_ratio", min_parallax_ratio, "[1, 100]");
  }
  if (!(target_parallax_px > 0 && target_parallax_px <= 1000)) {
    return OptionOutOfRange("sfm options", "target_parallax_px", target_parallax_px, "(0, 1000]");
  }
  if (min_registration_inliers < 6 || min_registration_inliers > 100000) {
    return OptionOutOfRange("sfm options", "min_registration_inliers", min_registration_inliers, "[6, 100000]");
  }
  if (!(metadata_focal_sigma_relative > 0 && metadata_focal_sigma_relative <= 1)) {
    return OptionOutOfRange("sfm options", "metadata_focal_sigma_relative", metadata_focal_sigma_relative, "(0, 1]");
  }
  if (!(focal_sweep_min >= 0.2 && focal_sweep_min < focal_sweep_max && focal_sweep_max <= 10)) {
    return OptionOutOfRange("sfm options",
                            "focal_sweep_min..max",
                            focal_sweep_min,
                            "0.2 <= min < max <= 10 (max " + std::to_string(focal_sweep_max) + ")");
  }
  if (!(min_rotation_for_focal_deg >= 0 && min_rotation_for_focal_deg <= 45)) {
    return OptionOutOfRange("sfm options", "min_rotation_for_focal_deg", min_rotation_for_focal_deg, "[0, 45]");
  }
  if (!(parallel_restart_max_rotation_deg >= 0 && parallel_restart_max_rotation_deg <= 45)) {
    return OptionOutOfRange(
        "sfm options", "parallel_restart_max_rotation_deg", parallel_restart_max_rotation_deg, "[0, 45]");
  }
  if (focal_sweep_steps < 3 || focal_sweep_steps > 100) {
    return OptionOutOfRange("sfm options", "focal_sweep_steps", focal_sweep_steps, "[3, 100]");
  }
  if (!(loss_scale_px > 0 && loss_scale_px <= 100))
    return OptionOutOfRange("sfm options", "loss_scale_px", loss_scale_px, "(0, 100]");
  if (!(outlier_error_px > 0 && outlier_error_px <= 100)) {
    return OptionOutOfRange("sfm options", "outlier_error_px", outlier_error_px, "(0, 100]");
  }
  if (!(median_depth > 0 && median_depth <= 1e6))
    return OptionOutOfRange("sfm options", "median_depth", median_depth, "(0, 1e6]");
  if (num_threads < 1 || num_threads > 64)
    return OptionOutOfRange("sfm options", "num_threads", num_threads, "[1, 64]");
  return OkStatus();
}

}  // namespace px::calib
