// The flat fallback: a "2D pan & scan" over one input view, for when depth or calibration cannot
// be trusted. The virtual camera stays at the view's own centre and only turns and zooms, so
// every frame is exactly a homography of that view's image (no depth, no holes) as long as the
// frame stays inside the image, which the plan guarantees. It follows the same framing rules as
// the 3D moves: a face ends slightly above centre at the close-up zoom (1.5f), two faces are
// panned between at equal size, a scene without subjects gets a slow zoom out across it; every
// subject stays wholly inside every frame where the image allows.
#pragma once

#include <cstdint>
#include <vector>

#include "pipeline/core/status.h"
#include "pipeline/core/view.h"
#include "pipeline/direct/camera_path.h"
#include "pipeline/direct/direct_options.h"

namespace px::direct {

// `seed` picks the direction (in or out, which side first). The path's kind is kPanZoom2d with
// source_views = {view.id}. Fails only for an invalid view camera.
StatusOr<CameraPath> PlanPanZoom2d(const View& view,
                                   const std::vector<Subject>& subjects,
                                   const DirectOptions& options);

// The homography taking `source`'s pixels to the frame of `camera` at `cam_from_world` (which
// must share the source's centre), for cv::warpPerspective.
cv::Matx33d FlatFrameHomography(const View& source, const CameraModel& camera, const Rigid3& cam_from_world);

// Whether the frame of `camera` at `cam_from_world` lies wholly inside `source`'s image.
bool FrameInsideSource(const View& source, const CameraModel& camera, const Rigid3& cam_from_world);

}  // namespace px::direct
