#include "pipeline/render/texture_stretch.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>

namespace px::render {

double TextureStretch(const Eigen::Matrix3d& novel_to_source,
                      const Eigen::Vector2d& novel_px,
                      double uniform_magnification) {
  const Eigen::Matrix3d& h = novel_to_source;
  const Eigen::Vector3d q = h * Eigen::Vector3d(novel_px.x(), novel_px.y(), 1.0);
  if (!(std::abs(q.z()) > 1e-12) || !(uniform_magnification > 0)) return 1.0;
  const double u = q.x() / q.z(), v = q.y() / q.z();
  // J = d(source px) / d(output px); its smaller singular value is the source distance covered by
  // one output pixel along the direction stretched most.
  const double j00 = (h(0, 0) - u * h(2, 0)) / q.z(), j01 = (h(0, 1) - u * h(2, 1)) / q.z();
  const double j10 = (h(1, 0) - v * h(2, 0)) / q.z(), j11 = (h(1, 1) - v * h(2, 1)) / q.z();
  const double a = j00 * j00 + j10 * j10, b = j00 * j01 + j10 * j11, c = j01 * j01 + j11 * j11;
  const double sigma_min_squared = 0.5 * (a + c - std::sqrt((a - c) * (a - c) + 4 * b * b));
  if (!(sigma_min_squared > 0)) return std::numeric_limits<double>::infinity();
  return 1.0 / (std::sqrt(sigma_min_squared) * uniform_magnification);
}

float TextureWeight(double stretch, const TextureStretchOptions& options) {
  if (options.fade_from <= 0 || !(stretch > options.fade_from)) return 1.0f;
  if (!(stretch < options.fade_to)) return 0.0f;
  return static_cast<float>((options.fade_to - stretch) / (options.fade_to - options.fade_from));
}

}  // namespace px::render
