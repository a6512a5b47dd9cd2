// The virtual camera's path through the scene: keyframes of position, orientation and focal
// length at normalised times, interpolated linearly (paper 4.2: "all parameters are linearly
// interpolated between the two endpoints"). Serialises to JSON so a clip can be re-rendered.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <nlohmann/json_fwd.hpp>

#include "pipeline/core/camera_model.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/status.h"
#include "pipeline/direct/direct_options.h"

namespace px {

struct CameraKeyframe {
  double t = 0;                                   // normalised time in [0, 1]
  Eigen::Vector3d centre_in_world = Eigen::Vector3d::Zero();  // camera centre, metres
  Eigen::Quaterniond cam_from_world_rotation = Eigen::Quaterniond::Identity();
  double focal_px = 0;                            // horizontal focal length in output pixels

  Rigid3 CamFromWorld() const;
};

struct CameraPath {
  std::string move;    // "establishing_dolly", ...
  std::string reason;  // why this move and these endpoints were chosen (for the clip's JSON)
  int width = 0;       // output image size in pixels
  int height = 0;
  double cx = 0;       // principal point in output pixels
  double cy = 0;
  double aspect = 1;   // fy / fx, kept from the source camera
  double fps = 30;     // frame rate the path is rendered at
  double duration_s = 5;
  std::vector<CameraKeyframe> keyframes;  // t ascending, first at 0, last at 1

  // At least two keyframes, t from 0 to 1 ascending, positive size and focal lengths.
  Status Validate() const;

  // Pose and focal length at normalised time t (clamped to [0, 1]): centre linear, rotation by
  // slerp, focal length linear, between the keyframes that bracket t.
  Rigid3 PoseAt(double t) const;
  double FocalAt(double t) const;
  // The output camera at t: pinhole, width x height, focal FocalAt(t), principal point (cx, cy).
  CameraModel CameraAt(double t) const;

  int NumFrames() const;
  // Normalised time of frame `index` of NumFrames(): first frame at 0, last at 1.
  double FrameTime(int index) const;
};

// Frames in a clip of `duration_s` at `fps`: round(fps * duration_s), at least 1.
int NumFrames(double fps, double duration_s);

nlohmann::json CameraPathToJson(const CameraPath& path);
// Reads what CameraPathToJson wrote; errors name the field ("camera_path.keyframes[1].focal_px: missing").
StatusOr<CameraPath> CameraPathFromJson(const nlohmann::json& j, const std::string& path = "camera_path");

}  // namespace px
