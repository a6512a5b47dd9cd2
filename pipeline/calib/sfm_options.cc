#include "pipeline/calib/sfm_options.h"

#include <sstream>
#include <string>

namespace px::calib {
namespace {

Status OutOfRange(const std::string& field, double value, const std::string& range) {
  std::ostringstream text;
  text << "sfm options: " << field << " = " << value << " is outside " << range;
  return InvalidArgumentError(text.str());
}

}  // namespace

Status SfmOptions::Validate() const {
  PX_RETURN_IF_ERROR(features.Validate().WithContext("sfm options"));
  PX_RETURN_IF_ERROR(matching.Validate().WithContext("sfm options"));
  PX_RETURN_IF_ERROR(ransac.Validate().WithContext("sfm options"));
  if (!(max_error_px > 0 && max_error_px <= 50)) return OutOfRange("max_error_px", max_error_px, "(0, 50]");
  if (min_pair_matches < 8 || min_pair_matches > 100000) {
    return OutOfRange("min_pair_matches", min_pair_matches, "[8, 100000]");
  }
  if (!(min_parallax_ratio >= 1 && min_parallax_ratio <= 100)) {
    return OutOfRange("min_parallax_ratio", min_parallax_ratio, "[1, 100]");
  }
  if (!(target_parallax_px > 0 && target_parallax_px <= 1000)) {
    return OutOfRange("target_parallax_px", target_parallax_px, "(0, 1000]");
  }
  if (min_registration_inliers < 6 || min_registration_inliers > 100000) {
    return OutOfRange("min_registration_inliers", min_registration_inliers, "[6, 100000]");
  }
  if (!(metadata_focal_sigma_relative > 0 && metadata_focal_sigma_relative <= 1)) {
    return OutOfRange("metadata_focal_sigma_relative", metadata_focal_sigma_relative, "(0, 1]");
  }
  if (!(focal_sweep_min >= 0.2 && focal_sweep_min < focal_sweep_max && focal_sweep_max <= 10)) {
    return OutOfRange("focal_sweep_min..max",
                      focal_sweep_min,
                      "0.2 <= min < max <= 10 (max " + std::to_string(focal_sweep_max) + ")");
  }
  if (!(min_rotation_for_focal_deg >= 0 && min_rotation_for_focal_deg <= 45)) {
    return OutOfRange("min_rotation_for_focal_deg", min_rotation_for_focal_deg, "[0, 45]");
  }
  if (!(parallel_restart_max_rotation_deg >= 0 && parallel_restart_max_rotation_deg <= 45)) {
    return OutOfRange("parallel_restart_max_rotation_deg", parallel_restart_max_rotation_deg, "[0, 45]");
  }
  if (focal_sweep_steps < 3 || focal_sweep_steps > 100) {
    return OutOfRange("focal_sweep_steps", focal_sweep_steps, "[3, 100]");
  }
  if (!(loss_scale_px > 0 && loss_scale_px <= 100)) return OutOfRange("loss_scale_px", loss_scale_px, "(0, 100]");
  if (!(outlier_error_px > 0 && outlier_error_px <= 100)) {
    return OutOfRange("outlier_error_px", outlier_error_px, "(0, 100]");
  }
  if (!(median_depth > 0 && median_depth <= 1e6)) return OutOfRange("median_depth", median_depth, "(0, 1e6]");
  if (num_threads < 1 || num_threads > 64) return OutOfRange("num_threads", num_threads, "[1, 64]");
  return OkStatus();
}

}  // namespace px::calib
