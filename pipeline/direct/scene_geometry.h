// What the direction stage needs to know about a capture's geometry (paper 4.2.1, 4.2.3): the
// capture plane and axis (the viewpoints spread across x-y and look down z), the viewpoints'
// bounding box in that frame, the capture's average focal length f, the output camera, and the
// scene's centroid and depth range from the depth maps.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "pipeline/core/camera_model.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/status.h"
#include "pipeline/core/view.h"

namespace px::direct {

struct SceneGeometry {
  int centre_index = 0;     // index into the views of the one nearest the centres' centroid
  CameraModel output;       // the clip's camera: the centre view's size and principal point, focal f
  double focal_px = 0;      // f: the views' mean horizontal focal, in output pixels
  double output_scale = 1;  // output pixels per centre-view pixel at f (the clip's size against the capture's)
  // The capture frame: origin at the centres' centroid, z the mean optical axis, x the mean image
  // right (made orthogonal), y = z x x (image down). For a lattice rig this is the rig frame.
  Rigid3 rig_from_world;
  Eigen::Vector2d box_min = Eigen::Vector2d::Zero();  // viewpoints' bounding box in rig x, y (metres)
  Eigen::Vector2d box_max = Eigen::Vector2d::Zero();
  Eigen::Vector3d up_in_world = Eigen::Vector3d(0, -1, 0);      // image up of the capture
  Eigen::Vector3d centroid_in_world = Eigen::Vector3d::Zero();  // per-axis median of the centre view's points
  // The surface the centre view sees where the centroid projects (what a frame aimed at the
  // centroid shows at its middle: the flowers in front of a bush, not the bush's median depth).
  Eigen::Vector3d centroid_surface_in_world = Eigen::Vector3d::Zero();
  double median_depth_m = 0;  // along the centre view's axis, known pixels only
  double near_depth_m = 0;    // 5th percentile of the same

  Eigen::Vector3d WorldFromRig(const Eigen::Vector3d& p_in_rig) const { return rig_from_world.Inverse() * p_in_rig; }
  Eigen::Vector3d RigFromWorld(const Eigen::Vector3d& p_in_world) const { return rig_from_world * p_in_world; }
  // The output camera with another focal length (same size, principal point and aspect).
  CameraModel OutputWithFocal(double focal_px) const;
};

// Fails (naming the problem) with fewer than one view, invalid cameras, views looking in
// opposite directions, or no known depth in the centre view. `depths` are matched by view id;
// the centre view needs one.
StatusOr<SceneGeometry> DescribeScene(const std::vector<View>& views, const std::vector<DepthMap>& depths);

// The centre view: nearest the centroid of the camera centres (ties: the first).
int CentreViewIndex(const std::vector<View>& views);

// The depth map with the view's id, or nullptr.
const DepthMap* FindDepth(const std::vector<DepthMap>& depths, ViewId id);

}  // namespace px::direct
