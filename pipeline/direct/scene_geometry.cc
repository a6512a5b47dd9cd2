#include "pipeline/direct/scene_geometry.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "pipeline/core/order_statistics.h"

namespace px::direct {

namespace {

// The surface `view` sees around where `point` projects: the median depth over a window an
// eighth of its width wide, along the point's ray. `point` itself where the window has no depth.
Eigen::Vector3d SurfaceAround(const View& view, const cv::Mat& depth_m, const Eigen::Vector3d& point) {
  const CameraModel pinhole = view.camera.WithoutDistortion();
  Eigen::Vector2d pixel;
  if (!pinhole.Project(view.cam_from_world * point, &pixel)) return point;
  const int radius = std::max(1, depth_m.cols / 16);
  const int u0 = static_cast<int>(std::lround(pixel.x())), v0 = static_cast<int>(std::lround(pixel.y()));
  std::vector<double> depths;
  for (int v = std::max(0, v0 - radius); v <= std::min(depth_m.rows - 1, v0 + radius); v += 2) {
    const float* row = depth_m.ptr<float>(v);
    for (int u = std::max(0, u0 - radius); u <= std::min(depth_m.cols - 1, u0 + radius); u += 2) {
      if (row[u] > 0 && std::isfinite(row[u])) depths.push_back(row[u]);
    }
  }
  if (depths.empty()) return point;
  return view.cam_from_world.Inverse() * (pinhole.Unproject(pixel) * Percentile(depths, 0.5));
}

}  // namespace

CameraModel SceneGeometry::OutputWithFocal(double focal) const {
  CameraModel camera = output;
  camera.fy = focal * output.fy / output.fx;
  camera.fx = focal;
  return camera;
}

int CentreViewIndex(const std::vector<View>& views) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const View& view : views) mean += CameraCentre(view.cam_from_world);
  mean /= std::max<size_t>(1, views.size());
  int best = 0;
  double best_distance = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < views.size(); ++i) {
    const double d = (CameraCentre(views[i].cam_from_world) - mean).norm();
    if (d < best_distance - 1e-12) {
      best_distance = d;
      best = static_cast<int>(i);
    }
  }
  return best;
}

const DepthMap* FindDepth(const std::vector<DepthMap>& depths, ViewId id) {
  for (const DepthMap& depth : depths) {
    if (depth.id == id) return &depth;
  }
  return nullptr;
}

StatusOr<SceneGeometry> DescribeScene(const std::vector<View>& views, const std::vector<DepthMap>& depths) {
  if (views.empty()) return InvalidArgumentError("direction: no views");
  SceneGeometry scene;
  Eigen::Vector3d axis_sum = Eigen::Vector3d::Zero();
  Eigen::Vector3d right_sum = Eigen::Vector3d::Zero();
  Eigen::Vector3d centre_sum = Eigen::Vector3d::Zero();
  for (const View& view : views) {
    PX_RETURN_IF_ERROR(view.camera.Validate().WithContext("direction: view " + std::to_string(view.id.value)));
    const Eigen::Matrix3d world_from_cam = view.cam_from_world.RotationMatrix().transpose();
    axis_sum += world_from_cam.col(2);
    right_sum += world_from_cam.col(0);
    centre_sum += CameraCentre(view.cam_from_world);
  }
  if (axis_sum.norm() < 0.5 * views.size()) {
    return FailedPreconditionError("direction: the " + std::to_string(views.size()) +
                                   " views look in directions more than 120 degrees apart; no capture plane");
  }
  const Eigen::Vector3d z = axis_sum.normalized();
  Eigen::Vector3d x = right_sum - right_sum.dot(z) * z;
  if (x.norm() < 1e-6) x = Eigen::Vector3d::UnitX() - z.x() * z;
  x.normalize();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d rig_from_world_rotation;
  rig_from_world_rotation.row(0) = x;
  rig_from_world_rotation.row(1) = y;
  rig_from_world_rotation.row(2) = z;
  const Eigen::Vector3d origin = centre_sum / static_cast<double>(views.size());
  scene.rig_from_world = Rigid3::FromMatrix(rig_from_world_rotation, -rig_from_world_rotation * origin);
  scene.up_in_world = -y;

  scene.box_min = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  scene.box_max = -scene.box_min;
  for (const View& view : views) {
    const Eigen::Vector3d p = scene.RigFromWorld(CameraCentre(view.cam_from_world));
    scene.box_min = scene.box_min.cwiseMin(p.head<2>());
    scene.box_max = scene.box_max.cwiseMax(p.head<2>());
  }

  scene.centre_index = CentreViewIndex(views);
  const View& centre = views[scene.centre_index];
  double focal_sum = 0;
  for (const View& view : views) focal_sum += view.camera.fx * centre.camera.width / view.camera.width;
  scene.focal_px = focal_sum / static_cast<double>(views.size());
  scene.output = centre.camera.WithoutDistortion();
  scene.output.fy = scene.focal_px * centre.camera.fy / centre.camera.fx;
  scene.output.fx = scene.focal_px;

  const DepthMap* depth = FindDepth(depths, centre.id);
  if (depth == nullptr || depth->depth_m.empty() || depth->depth_m.type() != CV_32F) {
    return FailedPreconditionError("direction: no depth map for the centre view " + std::to_string(centre.id.value));
  }
  // The centre view's points, every 4th pixel: their per-axis median is the scene's centroid
  // (a mean would be pulled to the far wall, which holds most pixels).
  std::vector<double> xs, ys, zs, axial;
  const Rigid3 world_from_cam = centre.cam_from_world.Inverse();
  const CameraModel pinhole = centre.camera.WithoutDistortion();
  for (int v = 2; v < depth->depth_m.rows; v += 4) {
    const float* row = depth->depth_m.ptr<float>(v);
    for (int u = 2; u < depth->depth_m.cols; u += 4) {
      const float d = row[u];
      if (!(d > 0) || !std::isfinite(d)) continue;
      const Eigen::Vector3d p = world_from_cam * (pinhole.Unproject(Eigen::Vector2d(u, v)) * d);
      xs.push_back(p.x());
      ys.push_back(p.y());
      zs.push_back(p.z());
      axial.push_back(d);
    }
  }
  if (axial.size() < 16) {
    return FailedPreconditionError("direction: the centre view " + std::to_string(centre.id.value) + " has depth at " +
                                   std::to_string(axial.size()) + " sampled pixels, want at least 16");
  }
  scene.centroid_in_world = Eigen::Vector3d(Percentile(xs, 0.5), Percentile(ys, 0.5), Percentile(zs, 0.5));
  scene.median_depth_m = Percentile(axial, 0.5);
  scene.near_depth_m = Percentile(axial, 0.05);
  scene.centroid_surface_in_world = SurfaceAround(centre, depth->depth_m, scene.centroid_in_world);
  return scene;
}

}  // namespace px::direct
