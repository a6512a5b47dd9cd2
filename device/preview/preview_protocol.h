// What passes between the daemon and an authoring session's preview worker (the daemon's own
// binary started with --preview-worker): JSON lines the daemon writes on the worker's stdin, and
// the worker's replies on its message fd (3), each a JSON line, a frame's line followed by its
// JPEG bytes.
//   -> {"capture_dir": "/store/captures/000007", "config": {...the daemon's config...}}
//   <- {"ok": true, "scene": {"views": [...], "focal_px": 830, "depth_min_m": .., "ms": 2400}}
//   -> {"frame": VIEWPOINT, "coverage": true, "draft": false}
//   <- {"ok": true, "bytes": 23410, "render_ms": 31, "hole_ratio": 0.01, "h_v": 0.2,
//       "camera": {"width", "height", "fx", "fy", "cx", "cy", "rotation", "translation"}}  + 23410 bytes
//      (h_v only when coverage was asked for: H(V) as the path planner judges a viewpoint, at the
//      size it verifies the clip's frames; an extra coverage pass, so a page asks for it when the
//      pointer rests, not on every frame of a drag; draft: a frame of a drag, drawn at half the
//      preview's size at most and enlarged; "lossless": true gives a PNG, not a JPEG; camera: the
//      one the frame was drawn with, cam_from_world's rotation row-major)
//   -> {"scene_export": true}
//   <- {"ok": true, "bytes": 44302336, "ms": 900}  + the scene for a browser's renderer
//      (pipeline/render/gl/web_scene.h)
//   -> {"probe": VIEWPOINT, "x": 320, "y": 240}
//   <- {"ok": true, "point_m": [x, y, z], "depth_m": 1.3}
//   -> {"region": VIEWPOINT, "rect": [x, y, w, h]}          a rectangle drawn on the preview
//   <- {"ok": true, "region_min_m": [..], "region_max_m": [..], "view": 4, "box_px": [x, y, w, h]}
//      (the 3D box a colour effect takes, and the box in the centre view a taxonomy move takes)
//   <- {"ok": false, "code": "INVALID_ARGUMENT", "message": "..."}       for any request
// VIEWPOINT: {"keyframe": <a shot keyframe, SHOT_FORMAT.md, focal_px in the clip's pixels>,
//             "width": 640, "height": 480,        the preview's size
//             "clip": {"width": 1200, "height": 800, "cx": 600, "cy": 400, "aspect": 1,
//                      "output_scale": 1}}        the clip's camera_path fields
// The preview is the clip's frame scaled to the preview's width: the same view, fewer pixels. A
// preview larger than the capture's detail is drawn at that detail and enlarged, as the clip is
// (pipeline/direct/detail_size.h).
#pragma once

#include <nlohmann/json.hpp>

#include "pipeline/core/status.h"
#include "pipeline/core/virtual_camera.h"

namespace px::device {

inline constexpr const char* kPreviewWorkerFlag = "--preview-worker";
inline constexpr int kPreviewMessageFd = 3;
// Preview frames are small: a request for more is refused.
inline constexpr int kMaxPreviewSide = 1920;

struct PreviewCamera {
  VirtualCamera camera;       // at the preview's size
  double output_scale = 1;    // preview pixels per capture pixel
  VirtualCamera clip_camera;  // the same viewpoint at the clip's size
  double verify_scale = 1;    // the fraction of the clip's size its path was checked at
};

// The virtual camera a VIEWPOINT describes; errors name the field. `capture_focal_px` resolves a
// keyframe's focal_scale.
StatusOr<PreviewCamera> PreviewCameraFromJson(const nlohmann::json& viewpoint, double capture_focal_px);

nlohmann::json PreviewErrorReply(const Status& status);

}  // namespace px::device
