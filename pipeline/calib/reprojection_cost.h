// The reprojection residual of bundle adjustment: a world point seen through a camera given by
// its rotation (unit quaternion w, x, y, z), centre and intrinsics block, with OpenCV's
// Brown-Conrady distortion; p1, p2, k3 and the aspect ratio fy / fx are held at the camera's.
// Two forms of one function: a template Ceres differentiates automatically (the reference), and
// the same residual with hand-derived Jacobians, which the solver uses: it is several times
// cheaper than 15-dimensional dual numbers, and adjustment time is mostly spent here.
#pragma once

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Core>

#include "pipeline/core/camera_model.h"

namespace px::calib {

// Intrinsics block layout: focal (fx; fy = aspect * fx), cx, cy, k1, k2.
constexpr int kIntrinsicsSize = 5;
constexpr int kFocal = 0, kCx = 1, kCy = 2, kK1 = 3, kK2 = 4;

// The held part of one observation: the observed pixel and the camera's fixed distortion terms.
struct ReprojectionTerms {
  ReprojectionTerms(const Eigen::Vector2d& observed, const CameraModel& camera)
      : u(observed.x()),
        v(observed.y()),
        aspect(camera.fy / camera.fx),
        p1(camera.distortion[2]),
        p2(camera.distortion[3]),
        k3(camera.distortion[4]) {}

  double u, v, aspect, p1, p2, k3;
};

struct ReprojectionCost {
  explicit ReprojectionCost(const ReprojectionTerms& terms) : terms(terms) {}

  template <typename T>
  bool operator()(const T* rotation, const T* centre, const T* intrinsics, const T* point, T* residual) const {
    const T offset[3] = {point[0] - centre[0], point[1] - centre[1], point[2] - centre[2]};
    T p[3];
    ceres::UnitQuaternionRotatePoint(rotation, offset, p);
    const T x = p[0] / p[2], y = p[1] / p[2];
    const T r2 = x * x + y * y;
    const T radial = T(1) + intrinsics[kK1] * r2 + intrinsics[kK2] * r2 * r2 + T(terms.k3) * r2 * r2 * r2;
    const T xd = x * radial + T(2 * terms.p1) * x * y + T(terms.p2) * (r2 + T(2) * x * x);
    const T yd = y * radial + T(terms.p1) * (r2 + T(2) * y * y) + T(2 * terms.p2) * x * y;
    residual[0] = intrinsics[kFocal] * xd + intrinsics[kCx] - T(terms.u);
    residual[1] = intrinsics[kFocal] * T(terms.aspect) * yd + intrinsics[kCy] - T(terms.v);
    return true;
  }

  ReprojectionTerms terms;
};

// ReprojectionCost with analytic Jacobians. The rotation's Jacobian is the exact derivative of the
// rotation for a unit quaternion; along the quaternion manifold's tangent, the only directions the
// solver uses, it equals the automatic one.
class AnalyticReprojectionCost final : public ceres::SizedCostFunction<2, 4, 3, kIntrinsicsSize, 3> {
 public:
  explicit AnalyticReprojectionCost(const ReprojectionTerms& terms) : terms_(terms) {}

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

 private:
  ReprojectionTerms terms_;
};

}  // namespace px::calib
