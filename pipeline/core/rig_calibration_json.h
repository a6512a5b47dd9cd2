// Versioned JSON for the rig calibration and its parts. Values in, values out: callers read and
// write the files. The schema is documented in FORMAT.md ("Rig calibration").
#pragma once

#include <nlohmann/json_fwd.hpp>
#include <string>

#include "pipeline/core/rig_calibration.h"

namespace px {

nlohmann::json CameraModelToJson(const CameraModel& camera);
// `path` names the object in error messages ("recording.rig.lenses[2].camera").
StatusOr<CameraModel> CameraModelFromJson(const nlohmann::json& j, const std::string& path = "camera");
nlohmann::json Rigid3ToJson(const Rigid3& pose);
StatusOr<Rigid3> Rigid3FromJson(const nlohmann::json& j, const std::string& path = "pose");
nlohmann::json LatticeLayoutToJson(const LatticeLayout& layout);
StatusOr<LatticeLayout> LatticeLayoutFromJson(const nlohmann::json& j, const std::string& path = "lattice");

nlohmann::json RigCalibrationToJson(const RigCalibration& rig);
// Rejects unknown schema versions, missing or mistyped fields, with the field's path in the
// message ("lenses[3].camera.fx: missing"), then runs RigCalibration::Validate.
StatusOr<RigCalibration> RigCalibrationFromJson(const nlohmann::json& j, const std::string& path = "");

std::string RigCalibrationToJsonText(const RigCalibration& rig);  // pretty-printed
StatusOr<RigCalibration> RigCalibrationFromJsonText(const std::string& text);

}  // namespace px
