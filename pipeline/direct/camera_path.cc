#include "pipeline/direct/camera_path.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <nlohmann/json.hpp>

#include "pipeline/core/json_fields.h"

namespace px {

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
  } else if (keyframes.size() < 2) {
    error << "has " << keyframes.size() << " keyframes, want at least 2";
  } else if (keyframes.front().t != 0.0 || keyframes.back().t != 1.0) {
    error << "keyframes span t = " << keyframes.front().t << " .. " << keyframes.back().t << ", want 0 .. 1";
  } else {
    for (size_t i = 0; i < keyframes.size(); ++i) {
      const CameraKeyframe& k = keyframes[i];
      if (i > 0 && !(k.t > keyframes[i - 1].t)) {
        error << "keyframes[" << i << "].t " << k.t << " does not increase";
        break;
      }
      if (!(k.focal_px > 0) || !std::isfinite(k.focal_px)) {
        error << "keyframes[" << i << "].focal_px " << k.focal_px << " is not positive";
        break;
      }
      if (!k.centre_in_world.allFinite()) {
        error << "keyframes[" << i << "].centre_in_world is not finite";
        break;
      }
    }
  }
  if (error.str().empty()) return OkStatus();
  return InvalidArgumentError("camera path: " + error.str());
}

namespace {

// Index i of the segment [keyframes[i], keyframes[i+1]] holding t, and the fraction within it.
std::pair<size_t, double> Segment(const std::vector<CameraKeyframe>& keyframes, double t) {
  PX_CHECK(keyframes.size() >= 2) << "camera path has " << keyframes.size() << " keyframes";
  t = std::clamp(t, keyframes.front().t, keyframes.back().t);
  size_t i = 0;
  while (i + 2 < keyframes.size() && t > keyframes[i + 1].t) ++i;
  const double span = keyframes[i + 1].t - keyframes[i].t;
  const double fraction = span > 0 ? (t - keyframes[i].t) / span : 0.0;
  return {i, std::clamp(fraction, 0.0, 1.0)};
}

}  // namespace

Rigid3 CameraPath::PoseAt(double t) const {
  const auto [i, f] = Segment(keyframes, t);
  return InterpolatePose(keyframes[i].CamFromWorld(), keyframes[i + 1].CamFromWorld(), f);
}

double CameraPath::FocalAt(double t) const {
  const auto [i, f] = Segment(keyframes, t);
  return (1.0 - f) * keyframes[i].focal_px + f * keyframes[i + 1].focal_px;
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

int NumFrames(double fps, double duration_s) {
  return std::max(1, static_cast<int>(std::lround(fps * duration_s)));
}

int CameraPath::NumFrames() const { return px::NumFrames(fps, duration_s); }

double CameraPath::FrameTime(int index) const {
  const int n = NumFrames();
  if (n <= 1) return 0.0;
  return std::clamp(static_cast<double>(index) / (n - 1), 0.0, 1.0);
}

nlohmann::json CameraPathToJson(const CameraPath& path) {
  nlohmann::json keyframes = nlohmann::json::array();
  for (const CameraKeyframe& k : path.keyframes) {
    const Eigen::Quaterniond& q = k.cam_from_world_rotation;
    keyframes.push_back({{"t", k.t},
                         {"centre_in_world_m", {k.centre_in_world.x(), k.centre_in_world.y(), k.centre_in_world.z()}},
                         {"cam_from_world_rotation_wxyz", {q.w(), q.x(), q.y(), q.z()}},
                         {"focal_px", k.focal_px}});
  }
  return nlohmann::json{{"move", path.move},
                        {"reason", path.reason},
                        {"width", path.width},
                        {"height", path.height},
                        {"cx", path.cx},
                        {"cy", path.cy},
                        {"aspect", path.aspect},
                        {"fps", path.fps},
                        {"duration_s", path.duration_s},
                        {"num_frames", path.NumFrames()},
                        {"keyframes", keyframes}};
}

StatusOr<CameraPath> CameraPathFromJson(const nlohmann::json& j, const std::string& where) {
  CameraPath path;
  PX_ASSIGN_OR_RETURN(path.move, json::GetString(j, "move", where));
  PX_ASSIGN_OR_RETURN(path.reason, json::GetStringOr(j, "reason", where, ""));
  PX_ASSIGN_OR_RETURN(int64_t width, json::GetInteger(j, "width", where));
  PX_ASSIGN_OR_RETURN(int64_t height, json::GetInteger(j, "height", where));
  path.width = static_cast<int>(width);
  path.height = static_cast<int>(height);
  PX_ASSIGN_OR_RETURN(path.cx, json::GetNumber(j, "cx", where));
  PX_ASSIGN_OR_RETURN(path.cy, json::GetNumber(j, "cy", where));
  PX_ASSIGN_OR_RETURN(path.aspect, json::GetNumberOr(j, "aspect", where, 1.0));
  PX_ASSIGN_OR_RETURN(path.fps, json::GetNumber(j, "fps", where));
  PX_ASSIGN_OR_RETURN(path.duration_s, json::GetNumber(j, "duration_s", where));
  PX_ASSIGN_OR_RETURN(const nlohmann::json* keyframes, json::GetField(j, "keyframes", where));
  const std::string keyframes_path = json::FieldPath(where, "keyframes");
  if (!keyframes->is_array()) return InvalidArgumentError(keyframes_path + ": want an array");
  for (size_t i = 0; i < keyframes->size(); ++i) {
    const nlohmann::json& k = (*keyframes)[i];
    const std::string kp = json::IndexPath(keyframes_path, i);
    CameraKeyframe keyframe;
    PX_ASSIGN_OR_RETURN(keyframe.t, json::GetNumber(k, "t", kp));
    PX_ASSIGN_OR_RETURN(std::vector<double> c, json::GetNumbers(k, "centre_in_world_m", kp, 3));
    PX_ASSIGN_OR_RETURN(std::vector<double> q, json::GetNumbers(k, "cam_from_world_rotation_wxyz", kp, 4));
    PX_ASSIGN_OR_RETURN(keyframe.focal_px, json::GetNumber(k, "focal_px", kp));
    const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (!(norm > 0.5 && norm < 1.5)) {
      return InvalidArgumentError(json::FieldPath(kp, "cam_from_world_rotation_wxyz") + ": quaternion norm " +
                                  std::to_string(norm) + " is not close to 1");
    }
    keyframe.centre_in_world = Eigen::Vector3d(c[0], c[1], c[2]);
    keyframe.cam_from_world_rotation = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized();
    path.keyframes.push_back(keyframe);
  }
  PX_RETURN_IF_ERROR(path.Validate().WithContext(where));
  return path;
}

}  // namespace px
