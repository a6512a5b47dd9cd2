// Pinhole camera with Brown-Conrady radial-tangential distortion (OpenCV's k1 k2 p1 p2 k3),
// intrinsics in pixels. Pixel centres are at integer coordinates (OpenCV convention).
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <array>
#include <opencv2/core.hpp>

#include "pipeline/core/status.h"

namespace px {

struct CameraModel {
  int width = 0;  // image size in pixels
  int height = 0;
  double fx = 0;  // focal lengths in pixels
  double fy = 0;
  double cx = 0;  // principal point in pixels
  double cy = 0;
  // OpenCV order: k1, k2, p1, p2, k3. All zero means an ideal pinhole.
  std::array<double, 5> distortion = {0, 0, 0, 0, 0};

  static CameraModel Pinhole(int width, int height, double focal_px);

  bool HasDistortion() const;
  // Positive size and focal lengths, principal point inside the image, finite coefficients.
  Status Validate() const;

  Eigen::Matrix3d K() const;
  cv::Matx33d CvK() const;
  cv::Mat CvDistortion() const;  // 1x5 CV_64F

  // Point in camera coordinates (z > 0 in front) -> distorted pixel. False if behind the camera.
  bool Project(const Eigen::Vector3d& p_in_cam, Eigen::Vector2d* pixel) const;
  // Distorted pixel -> unit-depth ray (x, y, 1) in camera coordinates (iterative undistortion).
  Eigen::Vector3d Unproject(const Eigen::Vector2d& pixel) const;

  // Normalised image coordinates (x/z, y/z) through the distortion model, and its inverse.
  Eigen::Vector2d Distort(const Eigen::Vector2d& normalized) const;
  Eigen::Vector2d Undistort(const Eigen::Vector2d& distorted_normalized) const;

  // The same camera for an image scaled by `factor` (intrinsics scale; distortion does not).
  CameraModel Scaled(double factor) const;
  // The same camera without distortion (for images already undistorted).
  CameraModel WithoutDistortion() const;
};

}  // namespace px
