// Authored shots (paper 4.4; format in pipeline/direct/SHOT_FORMAT.md): keyframes of position,
// direction, focal length, aperture, focus and colour effects along a cubic spline; moves from
// the taxonomy applied to regions the user marks; and two (or more) of either chained into one
// clip, each segment starting where the previous one ended. Parsed from a JSON value (device/
// reads the file); written back so that a clip's shot can be replayed or edited.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <nlohmann/json_fwd.hpp>
#include <opencv2/core/types.hpp>
#include <optional>
#include <string>
#include <vector>

#include "pipeline/core/status.h"
#include "pipeline/core/virtual_camera.h"
#include "pipeline/direct/camera_path.h"
#include "pipeline/direct/spline.h"

namespace px::direct {

struct ShotKeyframe {
  double t = 0;                                          // within its segment, [0, 1], increasing
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();  // camera centre (capture/rig frame)
  std::optional<Eigen::Vector3d> look_at_m;              // a point to look at, or
  std::optional<Eigen::Vector3d> direction;              // the optical axis (need not be unit)
  Eigen::Vector3d up = Eigen::Vector3d(0, -1, 0);        // image up (world), rolls nothing by default
  std::optional<double> focal_px;                        // focal length in output pixels, or
  std::optional<double> focal_scale;                     // relative to the capture's f (1.5 = close-up)
  double aperture_m = 0;                                 // 0 = pinhole
  std::optional<double> focus_depth_m;                   // in-focus depth along the axis, or
  std::optional<Eigen::Vector3d> focus_at_m;             // a point to keep in focus
  std::vector<ColorEffect> effects;
};

struct ShotSegment {
  double duration_s = 0;  // 0 = an equal share of what the other segments leave
  // Authored: keyframes (at least 2) along `interpolation`. Taxonomy: a move name ("auto",
  // "dolly_in", ...) with `effect` on `subjects` (empty: the detected faces).
  std::vector<ShotKeyframe> keyframes;
  Interpolation interpolation = Interpolation::kCatmullRom;
  std::string move;
  std::string effect = "auto";
  std::vector<cv::Rect2d> subjects_px;
  int subject_view = -1;  // view the rectangles are in; -1 = the centre view

  bool authored() const { return !keyframes.empty(); }
};

struct Shot {
  double fps = 0;         // 0 = the clip's setting
  double duration_s = 0;  // 0 = the sum of the segments' durations, else the clip's setting
  std::optional<uint64_t> seed;
  std::vector<ShotSegment> segments;  // at least one

  // Segment durations that sum to the clip's `duration_s` (explicit ones scaled if they exceed it).
  std::vector<double> SegmentDurations(double duration_s) const;
};

// Errors name the field: "shot.segments[1].keyframes[0].focal_px: want a number, got string".
StatusOr<Shot> ShotFromJson(const nlohmann::json& j, const std::string& where = "shot");
nlohmann::json ShotToJson(const Shot& shot);

// The shot that reproduces `path` exactly (one authored segment with its keyframes and
// interpolation): what `parallax clip` writes beside the clip.
Shot ShotFromPath(const CameraPath& path);

// An authored segment's keyframes as camera keyframes at segment time, with focal_scale
// resolved against `capture_focal_px` and focus_at resolved per key. Fails naming the key when
// neither a look-at point nor a direction is given, or both.
StatusOr<std::vector<CameraKeyframe>> ResolveKeyframes(const ShotSegment& segment,
                                                       double capture_focal_px,
                                                       const std::string& where);

}  // namespace px::direct
