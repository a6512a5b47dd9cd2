#include "pipeline/core/rig_calibration_json.h"

#include <cmath>
#include <nlohmann/json.hpp>

#include "pipeline/core/json_fields.h"

namespace px {

using Json = nlohmann::json;
using json::FieldPath;
using json::IndexPath;

Json CameraModelToJson(const CameraModel& c) {
  return Json{{"width", c.width},
              {"height", c.height},
              {"fx", c.fx},
              {"fy", c.fy},
              {"cx", c.cx},
              {"cy", c.cy},
              {"distortion_k1k2p1p2k3", std::vector<double>(c.distortion.begin(), c.distortion.end())}};
}

StatusOr<CameraModel> CameraModelFromJson(const Json& j, const std::string& path) {
  CameraModel c;
  PX_ASSIGN_OR_RETURN(int64_t width, json::GetInteger(j, "width", path));
  PX_ASSIGN_OR_RETURN(int64_t height, json::GetInteger(j, "height", path));
  c.width = static_cast<int>(width);
  c.height = static_cast<int>(height);
  PX_ASSIGN_OR_RETURN(c.fx, json::GetNumber(j, "fx", path));
  PX_ASSIGN_OR_RETURN(c.fy, json::GetNumber(j, "fy", path));
  PX_ASSIGN_OR_RETURN(c.cx, json::GetNumber(j, "cx", path));
  PX_ASSIGN_OR_RETURN(c.cy, json::GetNumber(j, "cy", path));
  if (j.contains("distortion_k1k2p1p2k3")) {
    PX_ASSIGN_OR_RETURN(std::vector<double> d, json::GetNumbers(j, "distortion_k1k2p1p2k3", path, 5));
    for (int i = 0; i < 5; ++i) c.distortion[i] = d[i];
  }
  PX_RETURN_IF_ERROR(c.Validate().WithContext(path.empty() ? "camera" : path));
  return c;
}

Json Rigid3ToJson(const Rigid3& pose) {
  const Eigen::Quaterniond& q = pose.rotation;
  return Json{{"rotation_wxyz", {q.w(), q.x(), q.y(), q.z()}},
              {"translation_m", {pose.translation.x(), pose.translation.y(), pose.translation.z()}}};
}

StatusOr<Rigid3> Rigid3FromJson(const Json& j, const std::string& path) {
  PX_ASSIGN_OR_RETURN(std::vector<double> q, json::GetNumbers(j, "rotation_wxyz", path, 4));
  PX_ASSIGN_OR_RETURN(std::vector<double> t, json::GetNumbers(j, "translation_m", path, 3));
  const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (!(norm > 0.5 && norm < 1.5)) {
    return InvalidArgumentError(FieldPath(path, "rotation_wxyz") + ": quaternion norm " + std::to_string(norm) +
                                " is not close to 1");
  }
  return Rigid3(Eigen::Quaterniond(q[0], q[1], q[2], q[3]), Eigen::Vector3d(t[0], t[1], t[2]));
}

Json LatticeLayoutToJson(const LatticeLayout& layout) {
  Json tiles = Json::array();
  for (const Tile& t : layout.tiles) {
    Json tile{{"row", t.row},
              {"col", t.col},
              {"rect_xywh", {t.rect.x, t.rect.y, t.rect.width, t.rect.height}},
              {"orientation", std::string(TileOrientationName(t.orientation))}};
    // Written only when set, so layouts of axis-aligned tiles read the same as before.
    if (t.rotation_deg != 0.0) tile["rotation_deg"] = t.rotation_deg;
    tiles.push_back(std::move(tile));
  }
  return Json{{"rows", layout.rows},
              {"cols", layout.cols},
              {"sensor_width", layout.sensor_width},
              {"sensor_height", layout.sensor_height},
              {"tiles", tiles}};
}

StatusOr<LatticeLayout> LatticeLayoutFromJson(const Json& j, const std::string& path) {
  LatticeLayout layout;
  PX_ASSIGN_OR_RETURN(int64_t rows, json::GetInteger(j, "rows", path));
  PX_ASSIGN_OR_RETURN(int64_t cols, json::GetInteger(j, "cols", path));
  PX_ASSIGN_OR_RETURN(int64_t sensor_width, json::GetInteger(j, "sensor_width", path));
  PX_ASSIGN_OR_RETURN(int64_t sensor_height, json::GetInteger(j, "sensor_height", path));
  layout.rows = static_cast<int>(rows);
  layout.cols = static_cast<int>(cols);
  layout.sensor_width = static_cast<int>(sensor_width);
  layout.sensor_height = static_cast<int>(sensor_height);
  PX_ASSIGN_OR_RETURN(const Json* tiles, json::GetField(j, "tiles", path));
  const std::string tiles_path = FieldPath(path, "tiles");
  if (!tiles->is_array()) return InvalidArgumentError(tiles_path + ": want an array");
  for (size_t i = 0; i < tiles->size(); ++i) {
    const Json& tj = (*tiles)[i];
    const std::string tile_path = IndexPath(tiles_path, i);
    Tile tile;
    PX_ASSIGN_OR_RETURN(int64_t row, json::GetInteger(tj, "row", tile_path));
    PX_ASSIGN_OR_RETURN(int64_t col, json::GetInteger(tj, "col", tile_path));
    PX_ASSIGN_OR_RETURN(std::vector<double> rect, json::GetNumbers(tj, "rect_xywh", tile_path, 4));
    PX_ASSIGN_OR_RETURN(std::string orientation, json::GetStringOr(tj, "orientation", tile_path, "upright"));
    tile.row = static_cast<int>(row);
    tile.col = static_cast<int>(col);
    tile.rect = cv::Rect(
        static_cast<int>(rect[0]), static_cast<int>(rect[1]), static_cast<int>(rect[2]), static_cast<int>(rect[3]));
    auto parsed = ParseTileOrientation(orientation);
    if (!parsed.ok()) return parsed.status().WithContext(FieldPath(tile_path, "orientation"));
    tile.orientation = *parsed;
    PX_ASSIGN_OR_RETURN(tile.rotation_deg, json::GetNumberOr(tj, "rotation_deg", tile_path, 0.0));
    layout.tiles.push_back(tile);
  }
  PX_RETURN_IF_ERROR(layout.Validate().WithContext(path.empty() ? "lattice" : path));
  return layout;
}

Json RigCalibrationToJson(const RigCalibration& rig) {
  Json lenses = Json::array();
  for (const LensCalibration& lens : rig.lenses) {
    lenses.push_back({{"camera", CameraModelToJson(lens.camera)}, {"cam_from_rig", Rigid3ToJson(lens.cam_from_rig)}});
  }
  Json j{{"schema", "parallax.rig_calibration"},
         {"version", RigCalibration::kSchemaVersion},
         {"rig_name", rig.rig_name},
         {"nominal_depth_m", {rig.nominal_depth_min_m, rig.nominal_depth_max_m}},
         {"lenses", lenses}};
  if (rig.lattice.rows > 0) j["lattice"] = LatticeLayoutToJson(rig.lattice);
  return j;
}

StatusOr<RigCalibration> RigCalibrationFromJson(const Json& j, const std::string& path) {
  RigCalibration rig;
  PX_ASSIGN_OR_RETURN(std::string schema, json::GetString(j, "schema", path));
  if (schema != "parallax.rig_calibration") {
    return InvalidArgumentError(FieldPath(path, "schema") + ": '" + schema + "' is not parallax.rig_calibration");
  }
  PX_ASSIGN_OR_RETURN(int64_t version, json::GetInteger(j, "version", path));
  if (version != RigCalibration::kSchemaVersion) {
    return InvalidArgumentError(FieldPath(path, "version") + ": " + std::to_string(version) +
                                " is not a supported version (this build reads " +
                                std::to_string(RigCalibration::kSchemaVersion) + ")");
  }
  PX_ASSIGN_OR_RETURN(rig.rig_name, json::GetStringOr(j, "rig_name", path, ""));
  if (j.contains("nominal_depth_m")) {
    PX_ASSIGN_OR_RETURN(std::vector<double> range, json::GetNumbers(j, "nominal_depth_m", path, 2));
    rig.nominal_depth_min_m = range[0];
    rig.nominal_depth_max_m = range[1];
  }
  if (j.contains("lattice")) {
    PX_ASSIGN_OR_RETURN(rig.lattice, LatticeLayoutFromJson(j["lattice"], FieldPath(path, "lattice")));
  }
  PX_ASSIGN_OR_RETURN(const Json* lenses, json::GetField(j, "lenses", path));
  const std::string lenses_path = FieldPath(path, "lenses");
  if (!lenses->is_array()) return InvalidArgumentError(lenses_path + ": want an array");
  for (size_t i = 0; i < lenses->size(); ++i) {
    const std::string lens_path = IndexPath(lenses_path, i);
    LensCalibration lens;
    PX_ASSIGN_OR_RETURN(const Json* camera, json::GetField((*lenses)[i], "camera", lens_path));
    PX_ASSIGN_OR_RETURN(lens.camera, CameraModelFromJson(*camera, FieldPath(lens_path, "camera")));
    PX_ASSIGN_OR_RETURN(const Json* pose, json::GetField((*lenses)[i], "cam_from_rig", lens_path));
    PX_ASSIGN_OR_RETURN(lens.cam_from_rig, Rigid3FromJson(*pose, FieldPath(lens_path, "cam_from_rig")));
    rig.lenses.push_back(lens);
  }
  PX_RETURN_IF_ERROR(rig.Validate());
  return rig;
}

std::string RigCalibrationToJsonText(const RigCalibration& rig) { return RigCalibrationToJson(rig).dump(2); }

StatusOr<RigCalibration> RigCalibrationFromJsonText(const std::string& text) {
  PX_ASSIGN_OR_RETURN(Json j, json::Parse(text, "rig calibration"));
  return RigCalibrationFromJson(j);
}

}  // namespace px
