#include "device/preview/preview_protocol.h"

#include <algorithm>
#include <string>

#include "pipeline/direct/camera_path.h"
#include "pipeline/direct/detail_size.h"
#include "pipeline/direct/shot_file.h"

namespace px::device {

namespace {

StatusOr<double> NumberField(const nlohmann::json& j, const char* name, const std::string& where) {
  if (!j.is_object() || !j.contains(name) || !j[name].is_number()) {
    return InvalidArgumentError(where + "." + name + ": missing or not a number");
  }
  return j[name].get<double>();
}

}  // namespace

StatusOr<PreviewCamera> PreviewCameraFromJson(const nlohmann::json& viewpoint, double capture_focal_px) {
  if (!viewpoint.is_object() || !viewpoint.contains("keyframe") || !viewpoint.contains("clip")) {
    return InvalidArgumentError("viewpoint: want an object with keyframe, width, height and clip");
  }
  PX_ASSIGN_OR_RETURN(const double width, NumberField(viewpoint, "width", "viewpoint"));
  PX_ASSIGN_OR_RETURN(const double height, NumberField(viewpoint, "height", "viewpoint"));
  if (width < 16 || height < 16 || width > kMaxPreviewSide || height > kMaxPreviewSide) {
    return InvalidArgumentError("viewpoint: " + std::to_string(static_cast<int>(width)) + "x" +
                                std::to_string(static_cast<int>(height)) + " is not within 16.." +
                                std::to_string(kMaxPreviewSide) + " pixels a side");
  }
  const nlohmann::json& clip = viewpoint["clip"];
  PX_ASSIGN_OR_RETURN(const double clip_width, NumberField(clip, "width", "viewpoint.clip"));
  PX_ASSIGN_OR_RETURN(const double clip_height, NumberField(clip, "height", "viewpoint.clip"));
  PX_ASSIGN_OR_RETURN(const double cx, NumberField(clip, "cx", "viewpoint.clip"));
  PX_ASSIGN_OR_RETURN(const double cy, NumberField(clip, "cy", "viewpoint.clip"));
  PX_ASSIGN_OR_RETURN(const double aspect, NumberField(clip, "aspect", "viewpoint.clip"));
  if (!(clip_width >= 16) || !(clip_height >= 16) || clip_width > 16384 || clip_height > 16384 || !(aspect > 0)) {
    return InvalidArgumentError("viewpoint.clip: width, height or aspect out of range");
  }

  // One keyframe read as the shot reader reads it (a segment needs two: the same one twice).
  nlohmann::json key = viewpoint["keyframe"];
  if (!key.is_object()) return InvalidArgumentError("viewpoint.keyframe: want an object");
  key["t"] = 0;
  nlohmann::json end = key;
  end["t"] = 1;
  const nlohmann::json shot_json = {{"segments", {{{"keyframes", {key, end}}}}}};
  PX_ASSIGN_OR_RETURN(direct::Shot shot, direct::ShotFromJson(shot_json, "viewpoint"));
  PX_ASSIGN_OR_RETURN(std::vector<CameraKeyframe> keys,
                      direct::ResolveKeyframes(shot.segments[0], capture_focal_px, "viewpoint.keyframe"));

  // The clip's own frame, and the same at the preview's width (focal length and principal point
  // scale with it).
  CameraPath path;
  path.width = static_cast<int>(clip_width);
  path.height = static_cast<int>(clip_height);
  path.cx = cx;
  path.cy = cy;
  path.aspect = aspect;
  path.keyframes = keys;
  PreviewCamera preview;
  preview.clip_camera = path.FrameAt(0);
  const double scale = width / clip_width;
  path.width = static_cast<int>(width);
  path.height = static_cast<int>(height);
  path.cx = cx * scale;
  path.cy = cy * scale;
  for (CameraKeyframe& k : path.keyframes) k.focal_px *= scale;
  preview.camera = path.FrameAt(0);
  PX_RETURN_IF_ERROR(preview.camera.Validate().WithContext("viewpoint"));
  const double clip_output_scale = std::max(1e-3, clip.value("output_scale", 1.0));
  preview.output_scale = clip_output_scale * scale;
  // As the planner verifies a path: at the capture's detail when the clip enlarges beyond it.
  preview.verify_scale = clip_output_scale > direct::kDrawAtDetailAbove ? 1 / clip_output_scale : 1.0;
  return preview;
}

nlohmann::json PreviewErrorReply(const Status& status) {
  return {{"ok", false}, {"code", std::string(StatusCodeName(status.code()))}, {"message", status.message()}};
}

}  // namespace px::device
