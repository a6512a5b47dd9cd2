#include "pipeline/core/camera_model.h"

#include <cmath>
#include <sstream>

namespace px {

CameraModel CameraModel::Pinhole(int width, int height, double focal_px) {
  CameraModel camera;
  camera.width = width;
  camera.height = height;
  camera.fx = focal_px;
  camera.fy = focal_px;
  camera.cx = (width - 1) * 0.5;
  camera.cy = (height - 1) * 0.5;
  return camera;
}

bool CameraModel::HasDistortion() const {
  for (double d : distortion) {
    if (d != 0.0) return true;
  }
  return false;
}

Status CameraModel::Validate() const {
  std::ostringstream error;
  if (width <= 0 || height <= 0) {
    error << "image size " << width << "x" << height << " is not positive";
  } else if (!(fx > 0) || !(fy > 0) || !std::isfinite(fx) || !std::isfinite(fy)) {
    error << "focal length fx=" << fx << " fy=" << fy << " is not positive and finite";
  } else if (!(cx >= -0.5 && cx <= width - 0.5 && cy >= -0.5 && cy <= height - 0.5)) {
    error << "principal point (" << cx << ", " << cy << ") lies outside the " << width << "x" << height << " image";
  } else {
    for (double d : distortion) {
      if (!std::isfinite(d)) error << "distortion coefficient " << d << " is not finite";
    }
  }
  if (error.str().empty()) return OkStatus();
  return InvalidArgumentError("camera model: " + error.str());
}

Eigen::Matrix3d CameraModel::K() const {
  Eigen::Matrix3d k;
  k << fx, 0, cx, 0, fy, cy, 0, 0, 1;
  return k;
}

cv::Matx33d CameraModel::CvK() const { return cv::Matx33d(fx, 0, cx, 0, fy, cy, 0, 0, 1); }

cv::Mat CameraModel::CvDistortion() const {
  cv::Mat d(1, 5, CV_64F);
  for (int i = 0; i < 5; ++i) d.at<double>(0, i) = distortion[i];
  return d;
}

Eigen::Vector2d CameraModel::Distort(const Eigen::Vector2d& n) const {
  const auto& [k1, k2, p1, p2, k3] = distortion;
  const double x = n.x(), y = n.y();
  const double r2 = x * x + y * y;
  const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
  return {x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x), y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y};
}

Eigen::Vector2d CameraModel::Undistort(const Eigen::Vector2d& d) const {
  if (!HasDistortion()) return d;
  // Gauss-Newton on Distort(n) = d with a numeric Jacobian; converges in a few steps for
  // the mild distortion of real lenses, and is exact to ~1e-12 in normalised units.
  Eigen::Vector2d n = d;
  for (int iter = 0; iter < 20; ++iter) {
    Eigen::Vector2d residual = Distort(n) - d;
    if (residual.squaredNorm() < 1e-24) break;
    constexpr double kStep = 1e-7;
    Eigen::Matrix2d jacobian;
    jacobian.col(0) = (Distort(n + Eigen::Vector2d(kStep, 0)) - Distort(n)) / kStep;
    jacobian.col(1) = (Distort(n + Eigen::Vector2d(0, kStep)) - Distort(n)) / kStep;
    n -= jacobian.inverse() * residual;
  }
  return n;
}

bool CameraModel::Project(const Eigen::Vector3d& p_in_cam, Eigen::Vector2d* pixel) const {
  if (p_in_cam.z() <= 1e-12) return false;
  Eigen::Vector2d n(p_in_cam.x() / p_in_cam.z(), p_in_cam.y() / p_in_cam.z());
  Eigen::Vector2d d = Distort(n);
  *pixel = Eigen::Vector2d(fx * d.x() + cx, fy * d.y() + cy);
  return true;
}

Eigen::Vector3d CameraModel::Unproject(const Eigen::Vector2d& pixel) const {
  Eigen::Vector2d d((pixel.x() - cx) / fx, (pixel.y() - cy) / fy);
  Eigen::Vector2d n = Undistort(d);
  return {n.x(), n.y(), 1.0};
}

CameraModel CameraModel::Scaled(double factor) const {
  CameraModel scaled = *this;
  scaled.width = static_cast<int>(std::lround(width * factor));
  scaled.height = static_cast<int>(std::lround(height * factor));
  scaled.fx = fx * factor;
  scaled.fy = fy * factor;
  // Pixel centres at integers: x' + 0.5 = (x + 0.5) * factor.
  scaled.cx = (cx + 0.5) * factor - 0.5;
  scaled.cy = (cy + 0.5) * factor - 0.5;
  return scaled;
}

CameraModel CameraModel::WithoutDistortion() const {
  CameraModel pinhole = *this;
  pinhole.distortion = {0, 0, 0, 0, 0};
  return pinhole;
}

}  // namespace px
