// Synthetic scenes with exact geometry for the calibration tests: random points in front of
// cameras, their noisy viewing rays and pixels. Header-only, tests only.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <vector>

#include "pipeline/core/camera_model.h"
#include "pipeline/core/rigid3.h"

namespace px::calib::testing {

inline Eigen::Quaterniond SmallRotation(double rx_deg, double ry_deg, double rz_deg) {
  const double k = M_PI / 180.0;
  return Eigen::Quaterniond(Eigen::AngleAxisd(rx_deg * k, Eigen::Vector3d::UnitX()) *
                            Eigen::AngleAxisd(ry_deg * k, Eigen::Vector3d::UnitY()) *
                            Eigen::AngleAxisd(rz_deg * k, Eigen::Vector3d::UnitZ()));
}

// `count` points uniformly in a box in front of the world origin: x, y in [-w, w], z in [z0, z1].
inline std::vector<Eigen::Vector3d> RandomPoints(
    int count, double half_width, double z_near, double z_far, cv::RNG& rng) {
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < count; ++i) {
    points.emplace_back(
        rng.uniform(-half_width, half_width), rng.uniform(-half_width, half_width), rng.uniform(z_near, z_far));
  }
  return points;
}

// The ray (x, y, 1) of `point` in the camera, with Gaussian pixel noise at `focal_px`.
inline Eigen::Vector3d NoisyRay(
    const Rigid3& cam_from_world, const Eigen::Vector3d& point, double focal_px, double noise_px, cv::RNG& rng) {
  const Eigen::Vector3d p = cam_from_world * point;
  return Eigen::Vector3d(
      p.x() / p.z() + rng.gaussian(noise_px) / focal_px, p.y() / p.z() + rng.gaussian(noise_px) / focal_px, 1.0);
}

// A ray in a random direction within the field of view: an outlier.
inline Eigen::Vector3d RandomRay(cv::RNG& rng) {
  return Eigen::Vector3d(rng.uniform(-0.5, 0.5), rng.uniform(-0.4, 0.4), 1.0);
}

}  // namespace px::calib::testing
