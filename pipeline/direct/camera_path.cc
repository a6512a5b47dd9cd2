#include "pipeline/direct/camera_path.h"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <sstream>

#include "pipeline/core/json_fields.h"

namespace px {

namespace {

constexpr PathKind kPathKinds[] = {PathKind::kNovelView, PathKind::kMorph, PathKind::kPanZoom2d};

nlohmann::json Vec3(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

StatusOr<Eigen::Vector3d> GetVec3(const nlohmann::json& j, const std::string& key, const std::string& where) {
  PX_ASSIGN_OR_RETURN(std::vector<double> v, json::GetNumbers(j, key, where, 3));
  return Eigen::Vector3d(v[0], v[1], v[2]);
}

std::vector<double> KeyTimes(const std::vector<CameraKeyframe>& keyframes) {
  std::vector<double> times;
  times.reserve(keyframes.size());
  for (const CameraKeyframe& k : keyframes) times.push_back(k.t);
  return times;
}

// A per-keyframe quantity gathered into one vector, for Interpolate.
template <typename T, typename Get>
std::vector<T> Gather(const std::vector<CameraKeyframe>& keyframes, Get get) {
  std::vector<T> values;
  values.reserve(keyframes.size());
  for (const CameraKeyframe& k : keyframes) values.push_back(get(k));
  return values;
}

}  // namespace

std::string_view PathKindName(PathKind kind) {
  switch (kind) {
    case PathKind::kNovelView:
      return "novel_view";
    case PathKind::kMorph:
      return "morph";
    case PathKind::kPanZoom2d:
      return "pan_zoom_2d";
  }
  return "unknown";
}

StatusOr<PathKind> ParsePathKind(std::string_view name) {
  for (PathKind kind : kPathKinds) {
    if (name == PathKindName(kind)) return kind;
  }
  return InvalidArgumentError("path kind '" + std::string(name) + "' is not one of novel_view, morph, pan_zoom_2d");
}

std::string_view InterpolationName(direct::Interpolation interpolation) {
  return interpolation == direct::Interpolation::kLinear ? "linear" : "catmull_rom";
}

StatusOr<direct::Interpolation> ParseInterpolation(std::string_view name) {
  if (name == "linear") return direct::Interpolation::kLinear;
  if (name == "catmull_rom") return direct::Interpolation::kCatmullRom;
  return InvalidArgumentError("interpolation '" + std::string(name) + "' is not one of linear, catmull_rom");
}

Rigid3 CameraKeyframe::CamFromWorld() const {
  return Rigid3(cam_from_world_rotation, -(cam_from_world_rotation.normalized() * centre_in_world));
}

Status CameraPath::Validate() const {
  std::ostringstream error;
  if (width <= 0 || height <= 0) {
    error << "output size " << width << "x" << height << " is not positive";
  } else if (!(aspect > 0) || !std::isfinite(aspect)) {
    error << "aspect " << aspect << " is not positive";
  } else if (!(fps > 0) || !(duration_s > 0)) {
    error << "fps " << fps << " or duration_s " << duration_s << " is not positive";
  } else if (Status timing_valid = timing.Validate(); !timing_valid.ok()) {
    error << timing_valid.message();
  } else if (keyframes.size() < 2) {
    error << "has " << keyframes.size() << " keyframes, want at least 2";
  } else if (keyframes.front().t != 0.0 || keyframes.back().t != 1.0) {
    error << "keyframes span t = " << keyframes.front().t << " .. " << keyframes.back().t << ", want 0 .. 1";
  } else if (kind == PathKind::kMorph && source_views.size() != 2) {
    error << "a morph needs 2 source_views, has " << source_views.size();
  } else if (kind == PathKind::kPanZoom2d && source_views.size() != 1) {
    error << "a pan and zoom needs 1 source view, has " << source_views.size();
  } else {
    const CameraKeyframe& first = keyframes.front();
    for (size_t i = 0; i < keyframes.size() && error.str().empty(); ++i) {
      const CameraKeyframe& k = keyframes[i];
      const std::string name = "keyframes[" + std::to_string(i) + "]";
      if (i > 0 && !(k.t > keyframes[i - 1].t)) {
        error << name << ".t " << k.t << " does not increase";
      } else if (!(k.focal_px > 0) || !std::isfinite(k.focal_px)) {
        error << name << ".focal_px " << k.focal_px << " is not positive";
      } else if (!k.centre_in_world.allFinite()) {
        error << name << ".centre_in_world is not finite";
      } else if (!(k.aperture_m >= 0) || !std::isfinite(k.aperture_m)) {
        error << name << ".aperture_m " << k.aperture_m << " is negative";
      } else if (k.aperture_m > 0 && !(k.focus_depth_m > 0 && std::isfinite(k.focus_depth_m))) {
        error << name << ".focus_depth_m " << k.focus_depth_m << " must be > 0 with aperture_m " << k.aperture_m;
      } else if (k.effects.size() != first.effects.size()) {
        error << name << ".effects has " << k.effects.size() << " layers, keyframes[0] has " << first.effects.size()
              << " (every keyframe lists the same layers)";
      } else {
        for (size_t e = 0; e < k.effects.size(); ++e) {
          const Status valid = k.effects[e].Validate();
          if (!valid.ok()) {
            error << name << ".effects[" << e << "]: " << valid.message();
            break;
          }
          if (k.effects[e].kind != first.effects[e].kind || k.effects[e].invert != first.effects[e].invert) {
            error << name << ".effects[" << e << "] is " << ColorEffectKindName(k.effects[e].kind)
                  << (k.effects[e].invert ? " (inverted)" : "") << ", keyframes[0] has "
                  << ColorEffectKindName(first.effects[e].kind) << (first.effects[e].invert ? " (inverted)" : "");
            break;
          }
        }
      }
    }
  }
  if (error.str().empty()) return OkStatus();
  return InvalidArgumentError("camera path: " + error.str());
}

Rigid3 CameraPath::PoseAt(double t) const {
  PX_CHECK(keyframes.size() >= 2) << "camera path has " << keyframes.size() << " keyframes";
  const std::vector<double> times = KeyTimes(keyframes);
  if (interpolation == direct::Interpolation::kLinear) {
    const auto [i, f] = direct::KeySpan(times, t);
    return InterpolatePose(keyframes[i].CamFromWorld(), keyframes[i + 1].CamFromWorld(), f);
  }
  const auto centres = Gather<Eigen::Vector3d>(keyframes, [](const CameraKeyframe& k) { return k.centre_in_world; });
  // World directions of the camera's +z (forward) and -y (image up).
  const auto forwards = Gather<Eigen::Vector3d>(keyframes, [](const CameraKeyframe& k) {
    return Eigen::Vector3d(k.cam_from_world_rotation.conjugate() * Eigen::Vector3d::UnitZ());
  });
  const auto ups = Gather<Eigen::Vector3d>(keyframes, [](const CameraKeyframe& k) {
    return Eigen::Vector3d(k.cam_from_world_rotation.conjugate() * -Eigen::Vector3d::UnitY());
  });
  const Eigen::Vector3d centre = direct::Interpolate(times, centres, t, interpolation);
  Eigen::Vector3d forward = direct::Interpolate(times, forwards, t, interpolation);
  const Eigen::Vector3d up = direct::Interpolate(times, ups, t, interpolation);
  if (forward.norm() < 1e-9) {  // keys looking in opposite directions: fall back to the rotation slerp
    const auto [i, f] = direct::KeySpan(times, t);
    forward = keyframes[i].cam_from_world_rotation.slerp(f, keyframes[i + 1].cam_from_world_rotation).conjugate() *
              Eigen::Vector3d::UnitZ();
  }
  return Rigid3::LookAt(centre, centre + forward.normalized(), up);
}

double CameraPath::FocalAt(double t) const {
  PX_CHECK(keyframes.size() >= 2) << "camera path has " << keyframes.size() << " keyframes";
  const auto focals = Gather<double>(keyframes, [](const CameraKeyframe& k) { return k.focal_px; });
  // A spline may overshoot between keys; never below the smallest key focal's tenth.
  const double floor = 0.1 * *std::min_element(focals.begin(), focals.end());
  return std::max(floor, direct::Interpolate(KeyTimes(keyframes), focals, t, interpolation));
}

CameraModel CameraPath::CameraAt(double t) const {
  CameraModel camera;
  camera.width = width;
  camera.height = height;
  camera.fx = FocalAt(t);
  camera.fy = camera.fx * aspect;
  camera.cx = cx;
  camera.cy = cy;
  return camera;
}

VirtualCamera CameraPath::FrameAt(double t) const {
  VirtualCamera frame;
  frame.camera = CameraAt(t);
  frame.cam_from_world = PoseAt(t);
  const std::vector<double> times = KeyTimes(keyframes);
  const auto apertures = Gather<double>(keyframes, [](const CameraKeyframe& k) { return k.aperture_m; });
  frame.aperture_m = std::max(0.0, direct::Interpolate(times, apertures, t, interpolation));
  if (frame.aperture_m > 0) {
    // A key without an aperture has no focus of its own: it takes its neighbours', so that a
    // depth-of-field ramp from a pinhole holds its focus.
    std::vector<double> focus;
    for (const CameraKeyframe& k : keyframes) focus.push_back(k.focus_depth_m);
    for (size_t i = 0; i < focus.size(); ++i) {
      if (focus[i] > 0) continue;
      for (size_t d = 1; d < focus.size(); ++d) {
        if (i + d < focus.size() && keyframes[i + d].focus_depth_m > 0) {
          focus[i] = keyframes[i + d].focus_depth_m;
          break;
        }
        if (i >= d && keyframes[i - d].focus_depth_m > 0) {
          focus[i] = keyframes[i - d].focus_depth_m;
          break;
        }
      }
    }
    const double floor = 1e-3;
    frame.focus_depth_m = std::max(floor, direct::Interpolate(times, focus, t, interpolation));
    if (!(*std::max_element(focus.begin(), focus.end()) > 0)) frame.aperture_m = 0;  // nothing to focus on
  }
  const size_t layers = keyframes.front().effects.size();
  for (size_t e = 0; e < layers; ++e) {
    ColorEffect effect = keyframes.front().effects[e];
    const auto amounts = Gather<double>(keyframes, [e](const CameraKeyframe& k) { return k.effects[e].amount; });
    const auto mins =
        Gather<Eigen::Vector3d>(keyframes, [e](const CameraKeyframe& k) { return k.effects[e].region_min_in_world; });
    const auto maxs =
        Gather<Eigen::Vector3d>(keyframes, [e](const CameraKeyframe& k) { return k.effects[e].region_max_in_world; });
    const auto falloffs = Gather<double>(keyframes, [e](const CameraKeyframe& k) { return k.effects[e].falloff_m; });
    effect.amount = std::clamp(direct::Interpolate(times, amounts, t, interpolation), 0.0, 10.0);
    const Eigen::Vector3d a = direct::Interpolate(times, mins, t, interpolation);
    const Eigen::Vector3d b = direct::Interpolate(times, maxs, t, interpolation);
    effect.region_min_in_world = a.cwiseMin(b);
    effect.region_max_in_world = a.cwiseMax(b);
    effect.falloff_m = std::max(1e-4, direct::Interpolate(times, falloffs, t, interpolation));
    frame.effects.push_back(effect);
  }
  return frame;
}

CameraPath BlankPath(PathKind kind, std::string move, const CameraModel& camera, double fps, double duration_s) {
  CameraPath path;
  path.kind = kind;
  path.move = std::move(move);
  path.effect = "none";
  path.width = camera.width;
  path.height = camera.height;
  path.cx = camera.cx;
  path.cy = camera.cy;
  path.aspect = camera.fy / camera.fx;
  path.fps = fps;
  path.duration_s = duration_s;
  return path;
}

int NumFrames(double fps, double duration_s) { return std::max(1, static_cast<int>(std::lround(fps * duration_s))); }

void FitPathToOutput(CameraPath* path, OutputSize size) {
  if (path->width == size.width && path->height == size.height) return;
  CameraModel source = CameraModel::Pinhole(path->width, path->height, 1.0);
  source.cx = path->cx;
  source.cy = path->cy;
  double scale = 1;
  const CameraModel framed = FrameOutputCamera(source, size, &scale);
  path->width = framed.width;
  path->height = framed.height;
  path->cx = framed.cx;
  path->cy = framed.cy;
  for (CameraKeyframe& key : path->keyframes) key.focal_px *= scale;
  path->output_scale *= scale;
}

int CameraPath::NumFrames() const { return timing.NumFrames(fps, duration_s); }

double CameraPath::FrameTime(int index) const { return timing.FrameTime(index, fps, duration_s); }

nlohmann::json SubjectToJson(const Subject& subject) {
  nlohmann::json corners = nlohmann::json::array();
  for (const Eigen::Vector3d& c : subject.corners_in_world) corners.push_back(Vec3(c));
  return {{"source", subject.source},
          {"view", subject.view},
          {"box_px", {subject.box_px.x, subject.box_px.y, subject.box_px.width, subject.box_px.height}},
          {"depth_m", subject.depth_m},
          {"depth_known", subject.depth_known},
          {"confident_fraction", subject.confident_fraction},
          {"score", subject.score},
          {"corners_in_world_m", corners}};
}

StatusOr<Subject> SubjectFromJson(const nlohmann::json& j, const std::string& where) {
  Subject subject;
  PX_ASSIGN_OR_RETURN(subject.source, json::GetStringOr(j, "source", where, "user"));
  PX_ASSIGN_OR_RETURN(int64_t view, json::GetIntegerOr(j, "view", where, -1));
  subject.view = static_cast<int32_t>(view);
  PX_ASSIGN_OR_RETURN(std::vector<double> box, json::GetNumbers(j, "box_px", where, 4));
  subject.box_px = cv::Rect2d(box[0], box[1], box[2], box[3]);
  PX_ASSIGN_OR_RETURN(subject.depth_m, json::GetNumberOr(j, "depth_m", where, 0.0));
  PX_ASSIGN_OR_RETURN(subject.depth_known, json::GetBoolOr(j, "depth_known", where, true));
  PX_ASSIGN_OR_RETURN(subject.confident_fraction, json::GetNumberOr(j, "confident_fraction", where, 1.0));
  PX_ASSIGN_OR_RETURN(subject.score, json::GetNumberOr(j, "score", where, 0.0));
  if (j.contains("corners_in_world_m")) {
    const std::string path = json::FieldPath(where, "corners_in_world_m");
    const nlohmann::json& corners = j.at("corners_in_world_m");
    if (!corners.is_array() || corners.size() != 4) return InvalidArgumentError(path + ": want 4 points");
    for (size_t i = 0; i < 4; ++i) {
      nlohmann::json holder = {{"p", corners[i]}};
      PX_ASSIGN_OR_RETURN(subject.corners_in_world[i], GetVec3(holder, "p", json::IndexPath(path, i)));
    }
  }
  return subject;
}

nlohmann::json ColorEffectToJson(const ColorEffect& effect) {
  return {{"kind", std::string(ColorEffectKindName(effect.kind))},
          {"amount", effect.amount},
          {"region_min_m", Vec3(effect.region_min_in_world)},
          {"region_max_m", Vec3(effect.region_max_in_world)},
          {"falloff_m", effect.falloff_m},
          {"invert", effect.invert}};
}

StatusOr<ColorEffect> ColorEffectFromJson(const nlohmann::json& j, const std::string& where) {
  ColorEffect effect;
  PX_ASSIGN_OR_RETURN(std::string kind, json::GetString(j, "kind", where));
  StatusOr<ColorEffectKind> parsed = ParseColorEffectKind(kind);
  if (!parsed.ok()) return parsed.status().WithContext(json::FieldPath(where, "kind"));
  effect.kind = *parsed;
  PX_ASSIGN_OR_RETURN(effect.amount, json::GetNumber(j, "amount", where));
  PX_ASSIGN_OR_RETURN(effect.region_min_in_world, GetVec3(j, "region_min_m", where));
  PX_ASSIGN_OR_RETURN(effect.region_max_in_world, GetVec3(j, "region_max_m", where));
  PX_ASSIGN_OR_RETURN(effect.falloff_m, json::GetNumberOr(j, "falloff_m", where, effect.falloff_m));
  PX_ASSIGN_OR_RETURN(effect.invert, json::GetBoolOr(j, "invert", where, false));
  PX_RETURN_IF_ERROR(effect.Validate().WithContext(where));
  return effect;
}

nlohmann::json CameraPathToJson(const CameraPath& path) {
  nlohmann::json keyframes = nlohmann::json::array();
  for (const CameraKeyframe& k : path.keyframes) {
    const Eigen::Quaterniond& q = k.cam_from_world_rotation;
    nlohmann::json key = {{"t", k.t},
                          {"centre_in_world_m", Vec3(k.centre_in_world)},
                          {"cam_from_world_rotation_wxyz", {q.w(), q.x(), q.y(), q.z()}},
                          {"focal_px", k.focal_px},
                          {"aperture_m", k.aperture_m},
                          {"focus_depth_m", k.focus_depth_m}};
    if (!k.effects.empty()) {
      nlohmann::json effects = nlohmann::json::array();
      for (const ColorEffect& e : k.effects) effects.push_back(ColorEffectToJson(e));
      key["effects"] = effects;
    }
    keyframes.push_back(key);
  }
  nlohmann::json subjects = nlohmann::json::array();
  for (const Subject& s : path.subjects) subjects.push_back(SubjectToJson(s));
  return nlohmann::json{{"kind", std::string(PathKindName(path.kind))},
                        {"move", path.move},
                        {"effect", path.effect},
                        {"reason", path.reason},
                        {"notes", path.notes},
                        {"source_views", path.source_views},
                        {"subjects", subjects},
                        {"interpolation", std::string(InterpolationName(path.interpolation))},
                        {"width", path.width},
                        {"height", path.height},
                        {"cx", path.cx},
                        {"cy", path.cy},
                        {"aspect", path.aspect},
                        {"fps", path.fps},
                        {"duration_s", path.duration_s},
                        {"style", std::string(ClipStyleName(path.timing.style))},
                        {"ease", std::string(ClipEaseName(path.timing.ease))},
                        {"hold_s", path.timing.hold_s},
                        {"output_scale", path.output_scale},
                        {"num_frames", path.NumFrames()},
                        {"keyframes", keyframes}};
}

StatusOr<CameraPath> CameraPathFromJson(const nlohmann::json& j, const std::string& where) {
  CameraPath path;
  PX_ASSIGN_OR_RETURN(std::string kind, json::GetStringOr(j, "kind", where, "novel_view"));
  StatusOr<PathKind> parsed_kind = ParsePathKind(kind);
  if (!parsed_kind.ok()) return parsed_kind.status().WithContext(json::FieldPath(where, "kind"));
  path.kind = *parsed_kind;
  PX_ASSIGN_OR_RETURN(path.move, json::GetString(j, "move", where));
  PX_ASSIGN_OR_RETURN(path.effect, json::GetStringOr(j, "effect", where, "none"));
  PX_ASSIGN_OR_RETURN(path.reason, json::GetStringOr(j, "reason", where, ""));
  if (j.contains("notes")) {
    const nlohmann::json& notes = j.at("notes");
    if (!notes.is_array()) return InvalidArgumentError(json::FieldPath(where, "notes") + ": want an array of strings");
    for (size_t i = 0; i < notes.size(); ++i) {
      if (!notes[i].is_string()) {
        return InvalidArgumentError(json::IndexPath(json::FieldPath(where, "notes"), i) + ": want a string");
      }
      path.notes.push_back(notes[i].get<std::string>());
    }
  }
  if (j.contains("source_views")) {
    PX_ASSIGN_OR_RETURN(std::vector<double> views, json::GetNumbers(j, "source_views", where));
    for (double v : views) path.source_views.push_back(static_cast<int32_t>(v));
  }
  if (j.contains("subjects")) {
    const nlohmann::json& subjects = j.at("subjects");
    const std::string subjects_path = json::FieldPath(where, "subjects");
    if (!subjects.is_array()) return InvalidArgumentError(subjects_path + ": want an array");
    for (size_t i = 0; i < subjects.size(); ++i) {
      PX_ASSIGN_OR_RETURN(Subject subject, SubjectFromJson(subjects[i], json::IndexPath(subjects_path, i)));
      path.subjects.push_back(std::move(subject));
    }
  }
  PX_ASSIGN_OR_RETURN(std::string interpolation, json::GetStringOr(j, "interpolation", where, "linear"));
  StatusOr<direct::Interpolation> parsed_interpolation = ParseInterpolation(interpolation);
  if (!parsed_interpolation.ok()) {
    return parsed_interpolation.status().WithContext(json::FieldPath(where, "interpolation"));
  }
  path.interpolation = *parsed_interpolation;
  PX_ASSIGN_OR_RETURN(int64_t width, json::GetInteger(j, "width", where));
  PX_ASSIGN_OR_RETURN(int64_t height, json::GetInteger(j, "height", where));
  path.width = static_cast<int>(width);
  path.height = static_cast<int>(height);
  PX_ASSIGN_OR_RETURN(path.cx, json::GetNumber(j, "cx", where));
  PX_ASSIGN_OR_RETURN(path.cy, json::GetNumber(j, "cy", where));
  PX_ASSIGN_OR_RETURN(path.aspect, json::GetNumberOr(j, "aspect", where, 1.0));
  PX_ASSIGN_OR_RETURN(path.fps, json::GetNumber(j, "fps", where));
  PX_ASSIGN_OR_RETURN(path.duration_s, json::GetNumber(j, "duration_s", where));
  // A path written without timing was the linear move played once.
  PX_ASSIGN_OR_RETURN(std::string style, json::GetStringOr(j, "style", where, "once"));
  PX_ASSIGN_OR_RETURN(std::string ease, json::GetStringOr(j, "ease", where, "linear"));
  StatusOr<ClipStyle> parsed_style = ParseClipStyle(style);
  if (!parsed_style.ok()) return parsed_style.status().WithContext(json::FieldPath(where, "style"));
  StatusOr<ClipEase> parsed_ease = ParseClipEase(ease);
  if (!parsed_ease.ok()) return parsed_ease.status().WithContext(json::FieldPath(where, "ease"));
  path.timing.style = *parsed_style;
  path.timing.ease = *parsed_ease;
  PX_ASSIGN_OR_RETURN(path.timing.hold_s, json::GetNumberOr(j, "hold_s", where, 0.0));
  if (Status timing = path.timing.Validate(); !timing.ok()) return timing.WithContext(where);
  PX_ASSIGN_OR_RETURN(path.output_scale, json::GetNumberOr(j, "output_scale", where, 1.0));
  PX_ASSIGN_OR_RETURN(const nlohmann::json* keyframes, json::GetField(j, "keyframes", where));
  const std::string keyframes_path = json::FieldPath(where, "keyframes");
  if (!keyframes->is_array()) return InvalidArgumentError(keyframes_path + ": want an array");
  for (size_t i = 0; i < keyframes->size(); ++i) {
    const nlohmann::json& k = (*keyframes)[i];
    const std::string kp = json::IndexPath(keyframes_path, i);
    CameraKeyframe keyframe;
    PX_ASSIGN_OR_RETURN(keyframe.t, json::GetNumber(k, "t", kp));
    PX_ASSIGN_OR_RETURN(keyframe.centre_in_world, GetVec3(k, "centre_in_world_m", kp));
    PX_ASSIGN_OR_RETURN(std::vector<double> q, json::GetNumbers(k, "cam_from_world_rotation_wxyz", kp, 4));
    PX_ASSIGN_OR_RETURN(keyframe.focal_px, json::GetNumber(k, "focal_px", kp));
    PX_ASSIGN_OR_RETURN(keyframe.aperture_m, json::GetNumberOr(k, "aperture_m", kp, 0.0));
    PX_ASSIGN_OR_RETURN(keyframe.focus_depth_m, json::GetNumberOr(k, "focus_depth_m", kp, 0.0));
    const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (!(norm > 0.5 && norm < 1.5)) {
      return InvalidArgumentError(json::FieldPath(kp, "cam_from_world_rotation_wxyz") + ": quaternion norm " +
                                  std::to_string(norm) + " is not close to 1");
    }
    keyframe.cam_from_world_rotation = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized();
    if (k.contains("effects")) {
      const nlohmann::json& effects = k.at("effects");
      const std::string ep = json::FieldPath(kp, "effects");
      if (!effects.is_array()) return InvalidArgumentError(ep + ": want an array");
      for (size_t e = 0; e < effects.size(); ++e) {
        PX_ASSIGN_OR_RETURN(ColorEffect effect, ColorEffectFromJson(effects[e], json::IndexPath(ep, e)));
        keyframe.effects.push_back(effect);
      }
    }
    path.keyframes.push_back(keyframe);
  }
  PX_RETURN_IF_ERROR(path.Validate().WithContext(where));
  return path;
}

}  // namespace px
