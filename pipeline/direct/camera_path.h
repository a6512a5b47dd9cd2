// The virtual camera's path through the scene: keyframes of position, orientation, focal length,
// lens (aperture, focus) and colour effects at normalised times, interpolated linearly (the
// taxonomy's moves, paper 4.2: "all parameters are linearly interpolated between the two
// endpoints") or along a Catmull-Rom spline (authored shots, paper 4.4). FrameAt(t) is what one
// clip frame asks of the renderer. Serialises to JSON (the clip's record, enough to re-render it).
//
// A path is rendered one of three ways (`kind`): novel views from the layered depth (the normal
// case), a morph between two input views (paper 4.5; two views or no trustworthy depth), or a
// flat pan and zoom over one input view (the last resort; a camera turning and zooming about
// that view's own centre sees exactly a homography of its image, so it needs no depth).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "pipeline/core/camera_model.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/status.h"
#include "pipeline/core/virtual_camera.h"
#include "pipeline/direct/clip_timing.h"
#include "pipeline/direct/direct_options.h"
#include "pipeline/direct/output_frame.h"
#include "pipeline/direct/spline.h"
#include "pipeline/direct/subject.h"

namespace px {

enum class PathKind {
  kNovelView,  // "novel_view": render every frame from the views with depth
  kMorph,      // "morph": morph between source_views[0] (t = 0) and source_views[1] (t = 1)
  kPanZoom2d,  // "pan_zoom_2d": warp source_views[0]'s image by the keyframes' rotation and zoom
};
std::string_view PathKindName(PathKind kind);
StatusOr<PathKind> ParsePathKind(std::string_view name);

std::string_view InterpolationName(direct::Interpolation interpolation);  // "linear", "catmull_rom"
StatusOr<direct::Interpolation> ParseInterpolation(std::string_view name);

struct CameraKeyframe {
  double t = 0;                                               // normalised time in [0, 1]
  Eigen::Vector3d centre_in_world = Eigen::Vector3d::Zero();  // camera centre, metres
  Eigen::Quaterniond cam_from_world_rotation = Eigen::Quaterniond::Identity();
  double focal_px = 0;       // horizontal focal length in output pixels
  double aperture_m = 0;     // thin-lens aperture diameter, metres; 0 = pinhole
  double focus_depth_m = 0;  // in-focus depth along the optical axis, metres; > 0 when aperture_m > 0
  // Colour-effect layers in force. Every keyframe of a path lists the same layers (kind and
  // invert) in the same order; amount, region and falloff are interpolated.
  std::vector<ColorEffect> effects;

  Rigid3 CamFromWorld() const;
};

struct CameraPath {
  PathKind kind = PathKind::kNovelView;
  std::string move;                   // "establishing_dolly", "dolly_zoom", "morph", "keyframes", ...
  std::string effect;                 // lens or colour effect of the move: "none", "dof_change", "focus_pull", ...
  std::string reason;                 // why this move and these endpoints were chosen (for the log and the clip's JSON)
  std::vector<std::string> notes;     // fallbacks taken and constraints that bit, one sentence each
  std::vector<int32_t> source_views;  // kMorph: the two views morphed; kPanZoom2d: the view warped
  std::vector<Subject> subjects;      // the subjects of interest the move was planned for
  direct::Interpolation interpolation = direct::Interpolation::kLinear;
  int width = 0;  // output image size in pixels
  int height = 0;
  double cx = 0;  // principal point in output pixels
  double cy = 0;
  double aspect = 1;      // fy / fx, kept from the source camera
  double fps = 30;        // frame rate the path is rendered at
  double duration_s = 5;  // the move's length (the clip's frames: timing.NumFrames)
  // How the frames walk the path. Default: the paper's linear move played once (what a path
  // written without timing meant); the planner sets DirectOptions::timing.
  ClipTiming timing{ClipStyle::kOnce, ClipEase::kLinear, 0};
  // Output pixels per pixel of the view the frame was cut from (> 1: upsampled beyond the
  // capture's detail); 1 when the clip has its source's size.
  double output_scale = 1;
  std::vector<CameraKeyframe> keyframes;  // t ascending, first at 0, last at 1

  // At least two keyframes, t from 0 to 1 ascending, positive size and focal lengths, lens and
  // effects valid and consistent across keyframes, source views as the kind needs.
  Status Validate() const;

  // Pose and focal length at normalised time t (clamped to [0, 1]). Linear: centre linear,
  // rotation by slerp, focal linear. Catmull-Rom: centre, viewing direction and up vector along
  // the spline (no roll is introduced), focal along the spline.
  Rigid3 PoseAt(double t) const;
  double FocalAt(double t) const;
  // The output camera at t: pinhole, width x height, focal FocalAt(t), principal point (cx, cy).
  CameraModel CameraAt(double t) const;
  // Everything one frame needs: camera, pose, aperture and focus (clamped to their ranges), and
  // the effect layers with interpolated amounts, regions and falloffs.
  VirtualCamera FrameAt(double t) const;

  int NumFrames() const;  // timing.NumFrames(fps, duration_s)
  // Normalised time of frame `index` of NumFrames() (timing.FrameTime): once, the first frame at
  // 0 and the move's last at 1.
  double FrameTime(int index) const;
};

// A path of `kind` with no keyframes yet, effect "none", at `camera`'s size, principal point and
// aspect, with the clip's timing: what every planner starts from.
CameraPath BlankPath(PathKind kind, std::string move, const CameraModel& camera, double fps, double duration_s);

// Re-frames a path cut from a view of the path's size to `size` (output_frame.h): focal lengths
// and principal point scaled as FrameOutputCamera does, output_scale multiplied. A path already
// of that size is left as it is.
void FitPathToOutput(CameraPath* path, OutputSize size);

// Frames in a clip of `duration_s` at `fps`: round(fps * duration_s), at least 1.
int NumFrames(double fps, double duration_s);

nlohmann::json SubjectToJson(const Subject& subject);
StatusOr<Subject> SubjectFromJson(const nlohmann::json& j, const std::string& where);
nlohmann::json ColorEffectToJson(const ColorEffect& effect);
StatusOr<ColorEffect> ColorEffectFromJson(const nlohmann::json& j, const std::string& where);

nlohmann::json CameraPathToJson(const CameraPath& path);
// Reads what CameraPathToJson wrote; errors name the field ("camera_path.keyframes[1].focal_px: missing").
// Fields added after the first version (kind, effect, lens, effects, subjects) are optional.
StatusOr<CameraPath> CameraPathFromJson(const nlohmann::json& j, const std::string& path = "camera_path");

}  // namespace px
