#include "pipeline/render/rays_in_views.h"

#include <Eigen/Core>
#include <Eigen/LU>

namespace px::render {

std::vector<RayInView> RaysInViews(const LayeredScene& scene, const CameraModel& camera, const Rigid3& cam_from_world) {
  const Eigen::Matrix3d k_inverse = camera.K().inverse();
  const Eigen::Matrix3d novel_to_world = cam_from_world.RotationMatrix().transpose();
  std::vector<RayInView> rays(scene.views().size());
  for (size_t v = 0; v < rays.size(); ++v) {
    const SceneView& view = scene.views()[v];
    // p_view = R_v (R_n^T (p_novel - t_n)) + t_v: the rotation and offset from output to view.
    const Eigen::Matrix3d rotation = view.cam_from_world.RotationMatrix() * novel_to_world;
    const Eigen::Vector3d offset = view.cam_from_world.translation - rotation * cam_from_world.translation;
    const Eigen::Matrix3d b = view.camera.K() * rotation * k_inverse;
    const Eigen::Vector3d a = view.camera.K() * offset;
    RayInView& ray = rays[v];
    for (int i = 0; i < 9; ++i) ray.b[i] = static_cast<float>(b(i / 3, i % 3));
    for (int i = 0; i < 3; ++i) ray.a[i] = static_cast<float>(a(i));
    ray.width = static_cast<float>(view.camera.width);
    ray.height = static_cast<float>(view.camera.height);
  }
  return rays;
}

}  // namespace px::render
