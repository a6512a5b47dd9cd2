#include "pipeline/render/color_effects.h"

#include <cmath>
#include <limits>

namespace px::render {

double EffectStrength(const ColorEffect& effect, const Eigen::Vector3d& point_in_world) {
  double strength = 0;
  if (point_in_world.allFinite()) {
    const Eigen::Vector3d outside = (effect.region_min_in_world - point_in_world)
                                        .cwiseMax(point_in_world - effect.region_max_in_world)
                                        .cwiseMax(Eigen::Vector3d::Zero());
    const double d2 = outside.squaredNorm();
    strength = std::exp(-d2 / (2.0 * effect.falloff_m * effect.falloff_m));
  }
  return effect.invert ? 1.0 - strength : strength;
}

void ApplyColorEffects(const std::vector<ColorEffect>& effects,
                       const CameraModel& camera,
                       const Rigid3& cam_from_world,
                       const cv::Mat& depth,
                       cv::Mat* colour) {
  if (effects.empty()) return;
  const Eigen::Matrix3d world_from_cam = cam_from_world.RotationMatrix().transpose();
  const Eigen::Vector3d centre = CameraCentre(cam_from_world);
  cv::parallel_for_(cv::Range(0, colour->rows), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      const float* z = depth.ptr<float>(y);
      cv::Vec3f* c = colour->ptr<cv::Vec3f>(y);
      for (int x = 0; x < colour->cols; ++x) {
        const Eigen::Vector3d ray((x - camera.cx) / camera.fx, (y - camera.cy) / camera.fy, 1.0);
        const double inf = std::numeric_limits<double>::infinity();
        const Eigen::Vector3d point =
            z[x] > 0 ? Eigen::Vector3d(centre + world_from_cam * (z[x] * ray)) : Eigen::Vector3d(inf, inf, inf);
        for (const ColorEffect& effect : effects) {
          const float s = static_cast<float>(EffectStrength(effect, point));
          if (s <= 0) continue;
          const float amount = static_cast<float>(effect.amount);
          cv::Vec3f e;
          switch (effect.kind) {
            case ColorEffectKind::kSaturation: {
              const float luma = 0.114f * c[x][0] + 0.587f * c[x][1] + 0.299f * c[x][2];
              e = cv::Vec3f(luma, luma, luma) + amount * (c[x] - cv::Vec3f(luma, luma, luma));
              break;
            }
            case ColorEffectKind::kBrightness:
              e = amount * c[x];
              break;
          }
          c[x] = (1.0f - s) * c[x] + s * e;
        }
      }
    }
  });
}

}  // namespace px::render
