// Stage 2: calibrated views. Each upright tile becomes a View: its image undistorted to the
// lens's own pinhole camera (same K, zero distortion) and its pose in the rig frame.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "pipeline/calib/calib_options.h"
#include "pipeline/calib/undistort_cache.h"
#include "pipeline/core/rig_calibration.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/status.h"
#include "pipeline/core/view.h"

namespace px {

// One view from one image: checks the image (CV_8UC3, exactly camera.width x camera.height) and
// the camera, undistorts the image if the camera has distortion (maps from `cache` when given),
// and returns View{id, undistorted image, camera without distortion, cam_from_world}. The image
// is always a fresh copy. Shared by lattice captures (below) and, later, image sets whose poses
// come from structure-from-motion. Errors name the view.
StatusOr<View> MakeView(ViewId id,
                        const cv::Mat& image,
                        const CameraModel& camera,
                        const Rigid3& cam_from_world,
                        const CalibOptions& options,
                        UndistortCache* cache = nullptr);

// All views of a lattice capture: upright_tiles[i] was taken by rig.lenses[i]; world = the rig
// frame, so each view's cam_from_world is its lens's cam_from_rig. Fails (naming the view) if the
// rig is invalid, the tile count differs from the lens count, or any tile cannot be made into a
// view; no view is skipped silently. Pass a cache that outlives the call to reuse maps between
// shots; without one, maps are still shared between lenses with identical intrinsics.
StatusOr<std::vector<View>> MakeViews(const std::vector<cv::Mat>& upright_tiles,
                                      const RigCalibration& rig,
                                      const CalibOptions& options,
                                      UndistortCache* cache = nullptr);

}  // namespace px
