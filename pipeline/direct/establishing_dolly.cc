#include "pipeline/direct/establishing_dolly.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

namespace px {

double MedianSceneDepth(const std::vector<DepthMap>& depths, int stride) {
  stride = std::max(1, stride);
  std::vector<float> samples;
  for (const DepthMap& map : depths) {
    if (map.depth_m.empty() || map.depth_m.type() != CV_32F) continue;
    for (int y = stride / 2; y < map.depth_m.rows; y += stride) {
      const float* row = map.depth_m.ptr<float>(y);
      for (int x = stride / 2; x < map.depth_m.cols; x += stride) {
        if (row[x] > 0 && std::isfinite(row[x])) samples.push_back(row[x]);
      }
    }
  }
  if (samples.empty()) return 0.0;
  auto middle = samples.begin() + static_cast<std::ptrdiff_t>(samples.size() / 2);
  std::nth_element(samples.begin(), middle, samples.end());
  return *middle;
}

StatusOr<CameraPath> PlanEstablishingDolly(const std::vector<View>& views, const std::vector<DepthMap>& depths,
                                           const DirectOptions& options) {
  PX_RETURN_IF_ERROR(options.Validate());
  if (views.size() < 2) {
    return FailedPreconditionError("establishing dolly: needs at least 2 views, got " +
                                   std::to_string(views.size()));
  }
  if (!depths.empty() && depths.size() != views.size()) {
    return InvalidArgumentError("establishing dolly: " + std::to_string(views.size()) + " views but " +
                                std::to_string(depths.size()) + " depth maps");
  }
  for (const View& view : views) {
    PX_RETURN_IF_ERROR(view.camera.Validate().WithContext("establishing dolly: view " +
                                                          std::to_string(view.id.value)));
  }

  // Bounding box of the camera centres, the mean optical axis and the mean image "up".
  Eigen::Vector3d box_min = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d box_max = -box_min;
  Eigen::Vector3d axis_sum = Eigen::Vector3d::Zero();
  Eigen::Vector3d up_sum = Eigen::Vector3d::Zero();
  for (const View& view : views) {
    const Eigen::Vector3d centre = CameraCentre(view.cam_from_world);
    box_min = box_min.cwiseMin(centre);
    box_max = box_max.cwiseMax(centre);
    const Eigen::Matrix3d world_from_cam = view.cam_from_world.RotationMatrix().transpose();
    axis_sum += world_from_cam.col(2);
    up_sum -= world_from_cam.col(1);  // OpenCV camera: +y is down in the image
  }
  const Eigen::Vector3d box_centre = 0.5 * (box_min + box_max);
  const Eigen::Vector3d extent = box_max - box_min;
  const int long_axis = extent.x() >= extent.y() ? 0 : 1;
  const double span_m = extent[long_axis];
  // A dolly needs a baseline: below a millimetre the views are one viewpoint (no parallax).
  constexpr double kMinSpanM = 1e-3;
  if (!(span_m >= kMinSpanM)) {
    return FailedPreconditionError("establishing dolly: the " + std::to_string(views.size()) +
                                   " view centres span " + std::to_string(span_m * 1000) +
                                   " mm in x and y, want at least 1 mm");
  }
  if (axis_sum.norm() < 1e-6) {
    return FailedPreconditionError("establishing dolly: the views look in opposite directions");
  }
  const Eigen::Vector3d mean_axis = axis_sum.normalized();

  // Intrinsics come from the view nearest the box centre ("the centre view").
  const View* centre_view = &views.front();
  double best_distance = std::numeric_limits<double>::infinity();
  for (const View& view : views) {
    const double d = (CameraCentre(view.cam_from_world) - box_centre).norm();
    if (d < best_distance) {
      best_distance = d;
      centre_view = &view;
    }
  }

  Eigen::Vector3d start = box_centre;
  Eigen::Vector3d end = box_centre;
  start[long_axis] = box_min[long_axis];
  end[long_axis] = box_max[long_axis];

  const double median_depth_m = MedianSceneDepth(depths);
  const bool converge = options.converge && median_depth_m > 0;
  const Eigen::Vector3d target = box_centre + mean_axis * (converge ? median_depth_m : 1.0);

  CameraPath path;
  path.move = "establishing_dolly";
  path.width = centre_view->camera.width;
  path.height = centre_view->camera.height;
  path.cx = centre_view->camera.cx;
  path.cy = centre_view->camera.cy;
  path.aspect = centre_view->camera.fy / centre_view->camera.fx;
  path.fps = options.fps;
  path.duration_s = options.duration_s;
  const Eigen::Vector3d ends[2] = {start, end};
  for (int i = 0; i < 2; ++i) {
    CameraKeyframe keyframe;
    keyframe.t = i;
    keyframe.centre_in_world = ends[i];
    // Straight ahead: the target is one metre along the mean axis from each end, not the centre.
    const Eigen::Vector3d look_at = converge ? target : Eigen::Vector3d(ends[i] + mean_axis);
    keyframe.cam_from_world_rotation = Rigid3::LookAt(ends[i], look_at, up_sum).rotation;
    keyframe.focal_px = centre_view->camera.fx;
    path.keyframes.push_back(keyframe);
  }

  char reason[256];
  const char* axis_name = long_axis == 0 ? "x" : "y";
  if (converge) {
    std::snprintf(reason, sizeof(reason),
                  "sideways along %s across the %.1f mm span of the %zu view centres, converging on the median "
                  "scene depth %.2f m",
                  axis_name, span_m * 1000, views.size(), median_depth_m);
  } else {
    std::snprintf(reason, sizeof(reason),
                  "sideways along %s across the %.1f mm span of the %zu view centres, looking straight ahead%s",
                  axis_name, span_m * 1000, views.size(),
                  options.converge ? " (no depth known to converge on)" : "");
  }
  path.reason = reason;
  PX_RETURN_IF_ERROR(path.Validate());
  return path;
}

}  // namespace px
