#include "pipeline/direct/shot_file.h"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "pipeline/core/json_fields.h"

namespace px::direct {

namespace {

constexpr int kShotVersion = 1;

nlohmann::json Vec3(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

StatusOr<Eigen::Vector3d> GetVec3(const nlohmann::json& j, const std::string& key, const std::string& where) {
  PX_ASSIGN_OR_RETURN(std::vector<double> v, json::GetNumbers(j, key, where, 3));
  const Eigen::Vector3d out(v[0], v[1], v[2]);
  if (!out.allFinite()) return InvalidArgumentError(json::FieldPath(where, key) + ": not finite");
  return out;
}

StatusOr<std::optional<Eigen::Vector3d>> GetOptionalVec3(const nlohmann::json& j,
                                                         const std::string& key,
                                                         const std::string& where) {
  if (!j.contains(key)) return std::optional<Eigen::Vector3d>();
  PX_ASSIGN_OR_RETURN(Eigen::Vector3d v, GetVec3(j, key, where));
  return std::optional<Eigen::Vector3d>(v);
}

StatusOr<std::optional<double>> GetOptionalNumber(const nlohmann::json& j,
                                                  const std::string& key,
                                                  const std::string& where) {
  if (!j.contains(key)) return std::optional<double>();
  PX_ASSIGN_OR_RETURN(double v, json::GetNumber(j, key, where));
  return std::optional<double>(v);
}

Status CheckKnownFields(const nlohmann::json& j, const std::vector<std::string>& known, const std::string& where) {
  if (!j.is_object()) return InvalidArgumentError(where + ": want an object");
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (it.key().rfind("_", 0) == 0 || it.key().rfind("comment", 0) == 0) continue;
    if (std::find(known.begin(), known.end(), it.key()) == known.end()) {
      std::string list;
      for (const std::string& k : known) list += (list.empty() ? "" : ", ") + k;
      return InvalidArgumentError(json::FieldPath(where, it.key()) + ": unknown field (known: " + list + ")");
    }
  }
  return OkStatus();
}

StatusOr<ShotKeyframe> KeyframeFromJson(const nlohmann::json& j, const std::string& where) {
  PX_RETURN_IF_ERROR(CheckKnownFields(j,
                                      {"t",
                                       "position_m",
                                       "look_at_m",
                                       "direction",
                                       "up",
                                       "focal_px",
                                       "focal_scale",
                                       "aperture_m",
                                       "focus_depth_m",
                                       "focus_at_m",
                                       "effects"},
                                      where));
  ShotKeyframe key;
  PX_ASSIGN_OR_RETURN(key.t, json::GetNumber(j, "t", where));
  PX_ASSIGN_OR_RETURN(key.position_m, GetVec3(j, "position_m", where));
  PX_ASSIGN_OR_RETURN(key.look_at_m, GetOptionalVec3(j, "look_at_m", where));
  PX_ASSIGN_OR_RETURN(key.direction, GetOptionalVec3(j, "direction", where));
  if (j.contains("up")) {
    PX_ASSIGN_OR_RETURN(key.up, GetVec3(j, "up", where));
  }
  PX_ASSIGN_OR_RETURN(key.focal_px, GetOptionalNumber(j, "focal_px", where));
  PX_ASSIGN_OR_RETURN(key.focal_scale, GetOptionalNumber(j, "focal_scale", where));
  PX_ASSIGN_OR_RETURN(key.aperture_m, json::GetNumberOr(j, "aperture_m", where, 0.0));
  PX_ASSIGN_OR_RETURN(key.focus_depth_m, GetOptionalNumber(j, "focus_depth_m", where));
  PX_ASSIGN_OR_RETURN(key.focus_at_m, GetOptionalVec3(j, "focus_at_m", where));
  if (key.look_at_m.has_value() == key.direction.has_value()) {
    return InvalidArgumentError(where + ": give one of look_at_m or direction");
  }
  if (key.direction && key.direction->norm() < 1e-9) return InvalidArgumentError(where + ".direction: zero vector");
  if (key.look_at_m && (*key.look_at_m - key.position_m).norm() < 1e-9) {
    return InvalidArgumentError(where + ".look_at_m: the camera's own position");
  }
  if (key.focal_px.has_value() == key.focal_scale.has_value()) {
    return InvalidArgumentError(where + ": give one of focal_px or focal_scale");
  }
  if (key.focal_px && !(*key.focal_px > 0 && std::isfinite(*key.focal_px))) {
    return InvalidArgumentError(where + ".focal_px: " + std::to_string(*key.focal_px) + " is not positive");
  }
  if (key.focal_scale && !(*key.focal_scale > 0.1 && *key.focal_scale <= 10)) {
    return InvalidArgumentError(where + ".focal_scale: " + std::to_string(*key.focal_scale) + " is outside (0.1, 10]");
  }
  if (!(key.aperture_m >= 0 && key.aperture_m <= 1)) {
    return InvalidArgumentError(where + ".aperture_m: " + std::to_string(key.aperture_m) + " is outside [0, 1]");
  }
  if (key.focus_depth_m && key.focus_at_m)
    return InvalidArgumentError(where + ": give focus_depth_m or focus_at_m, not both");
  if (key.focus_depth_m && !(*key.focus_depth_m > 0)) {
    return InvalidArgumentError(where + ".focus_depth_m: " + std::to_string(*key.focus_depth_m) + " is not positive");
  }
  if (key.aperture_m > 0 && !key.focus_depth_m && !key.focus_at_m) {
    return InvalidArgumentError(where + ": aperture_m " + std::to_string(key.aperture_m) +
                                " needs focus_depth_m or focus_at_m");
  }
  if (j.contains("effects")) {
    const nlohmann::json& effects = j.at("effects");
    const std::string path = json::FieldPath(where, "effects");
    if (!effects.is_array()) return InvalidArgumentError(path + ": want an array");
    for (size_t i = 0; i < effects.size(); ++i) {
      PX_ASSIGN_OR_RETURN(ColorEffect effect, ColorEffectFromJson(effects[i], json::IndexPath(path, i)));
      key.effects.push_back(effect);
    }
  }
  return key;
}

StatusOr<ShotSegment> SegmentFromJson(const nlohmann::json& j, const std::string& where) {
  PX_RETURN_IF_ERROR(CheckKnownFields(
      j, {"duration_s", "keyframes", "interpolation", "move", "effect", "subjects", "subject_view"}, where));
  ShotSegment segment;
  PX_ASSIGN_OR_RETURN(segment.duration_s, json::GetNumberOr(j, "duration_s", where, 0.0));
  if (!(segment.duration_s >= 0 && segment.duration_s <= 60)) {
    return InvalidArgumentError(where + ".duration_s: " + std::to_string(segment.duration_s) +
                                " is outside [0, 60] (0 = an equal share)");
  }
  const bool has_keys = j.contains("keyframes");
  const bool has_move = j.contains("move");
  if (has_keys == has_move) return InvalidArgumentError(where + ": give either keyframes or a move");
  if (has_keys) {
    const nlohmann::json& keys = j.at("keyframes");
    const std::string path = json::FieldPath(where, "keyframes");
    if (!keys.is_array() || keys.size() < 2)
      return InvalidArgumentError(path + ": want an array of at least 2 keyframes");
    for (size_t i = 0; i < keys.size(); ++i) {
      PX_ASSIGN_OR_RETURN(ShotKeyframe key, KeyframeFromJson(keys[i], json::IndexPath(path, i)));
      if (!segment.keyframes.empty() && !(key.t > segment.keyframes.back().t)) {
        return InvalidArgumentError(json::IndexPath(path, i) + ".t: " + std::to_string(key.t) + " does not increase");
      }
      segment.keyframes.push_back(key);
    }
    if (segment.keyframes.front().t != 0.0 || segment.keyframes.back().t != 1.0) {
      return InvalidArgumentError(path + ": t runs " + std::to_string(segment.keyframes.front().t) + " .. " +
                                  std::to_string(segment.keyframes.back().t) + ", want 0 .. 1");
    }
    PX_ASSIGN_OR_RETURN(std::string interpolation, json::GetStringOr(j, "interpolation", where, "catmull_rom"));
    StatusOr<Interpolation> parsed = ParseInterpolation(interpolation);
    if (!parsed.ok()) return parsed.status().WithContext(json::FieldPath(where, "interpolation"));
    segment.interpolation = *parsed;
  } else {
    PX_ASSIGN_OR_RETURN(segment.move, json::GetString(j, "move", where));
    if (!IsKnownMove(segment.move)) {
      return InvalidArgumentError(json::FieldPath(where, "move") + ": unknown move \"" + segment.move +
                                  "\", want one of " + KnownMovesText());
    }
    PX_ASSIGN_OR_RETURN(segment.effect, json::GetStringOr(j, "effect", where, "auto"));
    DirectOptions check;
    check.effect = segment.effect;
    if (Status valid = check.Validate(); !valid.ok()) {
      return InvalidArgumentError(json::FieldPath(where, "effect") + ": " + valid.message());
    }
    PX_ASSIGN_OR_RETURN(int64_t view, json::GetIntegerOr(j, "subject_view", where, -1));
    segment.subject_view = static_cast<int>(view);
    if (j.contains("subjects")) {
      const nlohmann::json& subjects = j.at("subjects");
      const std::string path = json::FieldPath(where, "subjects");
      if (!subjects.is_array()) return InvalidArgumentError(path + ": want an array of {\"box_px\": [x, y, w, h]}");
      for (size_t i = 0; i < subjects.size(); ++i) {
        const std::string sp = json::IndexPath(path, i);
        PX_RETURN_IF_ERROR(CheckKnownFields(subjects[i], {"box_px"}, sp));
        PX_ASSIGN_OR_RETURN(std::vector<double> box, json::GetNumbers(subjects[i], "box_px", sp, 4));
        if (!(box[2] > 0 && box[3] > 0)) {
          return InvalidArgumentError(json::FieldPath(sp, "box_px") + ": width and height must be positive");
        }
        segment.subjects_px.emplace_back(box[0], box[1], box[2], box[3]);
      }
    }
  }
  return segment;
}

nlohmann::json KeyframeToJson(const ShotKeyframe& key) {
  nlohmann::json j = {{"t", key.t}, {"position_m", Vec3(key.position_m)}};
  if (key.look_at_m) j["look_at_m"] = Vec3(*key.look_at_m);
  if (key.direction) j["direction"] = Vec3(*key.direction);
  j["up"] = Vec3(key.up);
  if (key.focal_px) j["focal_px"] = *key.focal_px;
  if (key.focal_scale) j["focal_scale"] = *key.focal_scale;
  j["aperture_m"] = key.aperture_m;
  if (key.focus_depth_m) j["focus_depth_m"] = *key.focus_depth_m;
  if (key.focus_at_m) j["focus_at_m"] = Vec3(*key.focus_at_m);
  if (!key.effects.empty()) {
    nlohmann::json effects = nlohmann::json::array();
    for (const ColorEffect& e : key.effects) effects.push_back(ColorEffectToJson(e));
    j["effects"] = effects;
  }
  return j;
}

}  // namespace

std::vector<double> Shot::SegmentDurations(double total_s) const {
  std::vector<double> durations;
  double given = 0;
  int unset = 0;
  for (const ShotSegment& s : segments) {
    given += s.duration_s;
    unset += s.duration_s > 0 ? 0 : 1;
  }
  const double scale = given > total_s && given > 0 ? total_s / given : 1.0;
  const double share = unset > 0 ? std::max(0.0, total_s - given * scale) / unset : 0.0;
  for (const ShotSegment& s : segments) durations.push_back(s.duration_s > 0 ? s.duration_s * scale : share);
  // Explicit durations that fall short of the total stretch to fill it.
  double sum = 0;
  for (double d : durations) sum += d;
  if (sum > 0 && std::abs(sum - total_s) > 1e-9) {
    for (double& d : durations) d *= total_s / sum;
  }
  return durations;
}

StatusOr<Shot> ShotFromJson(const nlohmann::json& j, const std::string& where) {
  PX_RETURN_IF_ERROR(CheckKnownFields(j, {"format", "version", "fps", "duration_s", "seed", "segments"}, where));
  Shot shot;
  PX_ASSIGN_OR_RETURN(std::string format, json::GetStringOr(j, "format", where, "parallax-shot"));
  if (format != "parallax-shot") {
    return InvalidArgumentError(json::FieldPath(where, "format") + ": '" + format + "', want 'parallax-shot'");
  }
  PX_ASSIGN_OR_RETURN(int64_t version, json::GetIntegerOr(j, "version", where, kShotVersion));
  if (version != kShotVersion) {
    return InvalidArgumentError(json::FieldPath(where, "version") + ": " + std::to_string(version) +
                                " is not supported (want " + std::to_string(kShotVersion) + ")");
  }
  PX_ASSIGN_OR_RETURN(shot.fps, json::GetNumberOr(j, "fps", where, 0.0));
  if (!(shot.fps == 0 || (shot.fps > 0 && shot.fps <= 240))) {
    return InvalidArgumentError(json::FieldPath(where, "fps") + ": " + std::to_string(shot.fps) +
                                " is outside (0, 240] (0 = the clip's)");
  }
  PX_ASSIGN_OR_RETURN(shot.duration_s, json::GetNumberOr(j, "duration_s", where, 0.0));
  if (!(shot.duration_s >= 0 && shot.duration_s <= 60)) {
    return InvalidArgumentError(json::FieldPath(where, "duration_s") + ": " + std::to_string(shot.duration_s) +
                                " is outside [0, 60]");
  }
  if (j.contains("seed")) {
    PX_ASSIGN_OR_RETURN(int64_t seed, json::GetInteger(j, "seed", where));
    if (seed < 0) return InvalidArgumentError(json::FieldPath(where, "seed") + ": negative");
    shot.seed = static_cast<uint64_t>(seed);
  }
  PX_ASSIGN_OR_RETURN(const nlohmann::json* segments, json::GetField(j, "segments", where));
  const std::string path = json::FieldPath(where, "segments");
  if (!segments->is_array() || segments->empty()) return InvalidArgumentError(path + ": want a non-empty array");
  for (size_t i = 0; i < segments->size(); ++i) {
    PX_ASSIGN_OR_RETURN(ShotSegment segment, SegmentFromJson((*segments)[i], json::IndexPath(path, i)));
    shot.segments.push_back(std::move(segment));
  }
  return shot;
}

nlohmann::json ShotToJson(const Shot& shot) {
  nlohmann::json segments = nlohmann::json::array();
  for (const ShotSegment& s : shot.segments) {
    nlohmann::json segment = {{"duration_s", s.duration_s}};
    if (s.authored()) {
      nlohmann::json keys = nlohmann::json::array();
      for (const ShotKeyframe& k : s.keyframes) keys.push_back(KeyframeToJson(k));
      segment["keyframes"] = keys;
      segment["interpolation"] = std::string(InterpolationName(s.interpolation));
    } else {
      segment["move"] = s.move;
      segment["effect"] = s.effect;
      if (!s.subjects_px.empty()) {
        nlohmann::json subjects = nlohmann::json::array();
        for (const cv::Rect2d& r : s.subjects_px) subjects.push_back({{"box_px", {r.x, r.y, r.width, r.height}}});
        segment["subjects"] = subjects;
        segment["subject_view"] = s.subject_view;
      }
    }
    segments.push_back(segment);
  }
  nlohmann::json j = {{"format", "parallax-shot"},
                      {"version", kShotVersion},
                      {"fps", shot.fps},
                      {"duration_s", shot.duration_s},
                      {"segments", segments}};
  if (shot.seed) j["seed"] = *shot.seed;
  return j;
}

Shot ShotFromPath(const CameraPath& path) {
  Shot shot;
  shot.fps = path.fps;
  shot.duration_s = path.duration_s;
  ShotSegment segment;
  segment.duration_s = path.duration_s;
  segment.interpolation = path.interpolation;
  for (const CameraKeyframe& k : path.keyframes) {
    ShotKeyframe key;
    key.t = k.t;
    key.position_m = k.centre_in_world;
    key.direction = k.cam_from_world_rotation.conjugate() * Eigen::Vector3d::UnitZ();
    key.up = k.cam_from_world_rotation.conjugate() * -Eigen::Vector3d::UnitY();
    key.focal_px = k.focal_px;
    key.aperture_m = k.aperture_m;
    if (k.focus_depth_m > 0) key.focus_depth_m = k.focus_depth_m;
    if (key.aperture_m > 0 && !key.focus_depth_m) key.aperture_m = 0;
    key.effects = k.effects;
    segment.keyframes.push_back(key);
  }
  shot.segments.push_back(segment);
  return shot;
}

StatusOr<std::vector<CameraKeyframe>> ResolveKeyframes(const ShotSegment& segment,
                                                       double capture_focal_px,
                                                       const std::string& where) {
  std::vector<CameraKeyframe> keys;
  for (size_t i = 0; i < segment.keyframes.size(); ++i) {
    const ShotKeyframe& k = segment.keyframes[i];
    const std::string kp = where + ".keyframes[" + std::to_string(i) + "]";
    const Eigen::Vector3d direction = k.direction ? *k.direction : Eigen::Vector3d(*k.look_at_m - k.position_m);
    if (direction.norm() < 1e-9) return InvalidArgumentError(kp + ": no direction to look in");
    if (direction.normalized().cross(k.up.normalized()).norm() < 1e-6) {
      return InvalidArgumentError(kp + ".up: parallel to the viewing direction");
    }
    CameraKeyframe key;
    key.t = k.t;
    key.centre_in_world = k.position_m;
    key.cam_from_world_rotation = Rigid3::LookAt(k.position_m, k.position_m + direction.normalized(), k.up).rotation;
    key.focal_px = k.focal_px ? *k.focal_px : *k.focal_scale * capture_focal_px;
    key.aperture_m = k.aperture_m;
    if (k.focus_depth_m) {
      key.focus_depth_m = *k.focus_depth_m;
    } else if (k.focus_at_m) {
      key.focus_depth_m = (key.CamFromWorld() * *k.focus_at_m).z();
      if (!(key.focus_depth_m > 0)) {
        return InvalidArgumentError(kp + ".focus_at_m: behind the camera (depth " + std::to_string(key.focus_depth_m) +
                                    " m)");
      }
    }
    key.effects = k.effects;
    keys.push_back(key);
  }
  return keys;
}

}  // namespace px::direct
