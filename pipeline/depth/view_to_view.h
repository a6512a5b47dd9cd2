// A reference view's pixel at a depth, as another view sees it: where it lands and how far it is
// from that camera. The consistency and free-space checks compare it with that view's own depth.
#pragma once

#include <Eigen/Dense>
#include <cmath>

#include "pipeline/core/view.h"

namespace px::depth {

class ViewToView {
 public:
  ViewToView(const View& reference, const View& other) : a_(reference.camera), b_(other.camera) {
    const Rigid3 other_from_ref = other.cam_from_world * reference.cam_from_world.Inverse();
    rotation_ = other_from_ref.RotationMatrix();
    translation_ = other_from_ref.translation;
    // Disparity of inverse depth u in the other view is about focal * baseline * u.
    focal_baseline_ = b_.fx * translation_.norm();
  }

  // Pixels of disparity per unit of inverse depth (1/m); 0 for views at one centre.
  double focal_baseline() const { return focal_baseline_; }

  // Pixel (x, y) of the reference at depth z (metres): false when it lands behind the other
  // camera or outside its width x height; else its nearest pixel (u, v) there and its depth.
  bool Project(double x, double y, double z, int* u, int* v, double* z_other) const {
    const Eigen::Vector3d in_ref((x - a_.cx) / a_.fx * z, (y - a_.cy) / a_.fy * z, z);
    const Eigen::Vector3d p = rotation_ * in_ref + translation_;
    if (p.z() <= 0) return false;
    const long pu = std::lround(b_.fx * p.x() / p.z() + b_.cx);
    const long pv = std::lround(b_.fy * p.y() / p.z() + b_.cy);
    if (pu < 0 || pv < 0 || pu >= b_.width || pv >= b_.height) return false;
    *u = static_cast<int>(pu);
    *v = static_cast<int>(pv);
    *z_other = p.z();
    return true;
  }

 private:
  CameraModel a_, b_;
  Eigen::Matrix3d rotation_;
  Eigen::Vector3d translation_;
  double focal_baseline_ = 0;
};

}  // namespace px::depth
