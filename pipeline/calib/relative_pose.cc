#include "pipeline/calib/relative_pose.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <opencv2/calib3d.hpp>
#include <opengv/relative_pose/CentralRelativeAdapter.hpp>
#include <opengv/relative_pose/methods.hpp>
#include <opengv/sac_problems/relative_pose/CentralRelativePoseSacProblem.hpp>
#include <opengv/sac_problems/relative_pose/RotationOnlySacProblem.hpp>

#include "pipeline/calib/opengv_ransac.h"
#include "pipeline/core/order_statistics.h"

namespace px::calib {
namespace {

using opengv::sac_problems::relative_pose::CentralRelativePoseSacProblem;
using opengv::sac_problems::relative_pose::RotationOnlySacProblem;

constexpr int kMinRelativePoseCorrespondences = 8;

// Angle between two rays, accurate for small angles (atan2 of the cross and dot products).
double AngleBetween(const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
  return std::atan2(u.cross(v).norm(), u.dot(v));
}

// How well one homography explains `subset`: the fraction within `threshold_px` and the 90th
// percentile of the transfer error (points in pixels at `focal_px`, where OpenCV's conditioning works as meant).
// The homography is RANSAC's at `ransac_threshold_px`, refined by OpenCV on its inliers.
void FitHomography(const std::vector<Eigen::Vector3d>& rays_a,
                   const std::vector<Eigen::Vector3d>& rays_b,
                   const std::vector<int>& subset,
                   double focal_px,
                   double ransac_threshold_px,
                   double threshold_px,
                   double* fraction,
                   double* p90_error_px) {
  *fraction = 0;
  *p90_error_px = std::numeric_limits<double>::infinity();
  std::vector<cv::Point2d> a, b;
  for (int i : subset) {
    if (rays_a[i].z() <= 0 || rays_b[i].z() <= 0) continue;
    a.emplace_back(focal_px * rays_a[i].x() / rays_a[i].z(), focal_px * rays_a[i].y() / rays_a[i].z());
    b.emplace_back(focal_px * rays_b[i].x() / rays_b[i].z(), focal_px * rays_b[i].y() / rays_b[i].z());
  }
  if (a.size() < 8) return;
  std::vector<uchar> mask;
  const cv::Mat h = cv::findHomography(a, b, cv::RANSAC, ransac_threshold_px, mask, 2000, 0.999);
  if (h.empty()) return;
  // Measured against the returned (least-squares refined) homography: RANSAC's own mask comes
  // from a minimal-sample model and misses a few inliers.
  const cv::Matx33d hm(h);
  std::vector<double> errors;
  int explained = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    const cv::Vec3d p = hm * cv::Vec3d(a[i].x, a[i].y, 1.0);
    const double error =
        p[2] == 0 ? std::numeric_limits<double>::infinity() : std::hypot(p[0] / p[2] - b[i].x, p[1] / p[2] - b[i].y);
    errors.push_back(error);
    explained += error < threshold_px ? 1 : 0;
  }
  *fraction = static_cast<double>(explained) / static_cast<double>(subset.size());
  *p90_error_px = Percentile(errors, 0.9);
}

// Sampson distances of the inliers to the essential matrix of (R, t) = b_from_a, in normalised
// units: each correspondence's first-order distance to its epipolar constraint.
std::vector<double> SampsonErrors(const opengv::bearingVectors_t& bearings_b,
                                  const opengv::bearingVectors_t& bearings_a,
                                  const opengv::transformation_t& b_from_a,
                                  const std::vector<int>& inliers) {
  const Eigen::Vector3d t = b_from_a.col(3).normalized();
  Eigen::Matrix3d t_cross;
  t_cross << 0, -t.z(), t.y(), t.z(), 0, -t.x(), -t.y(), t.x(), 0;
  const Eigen::Matrix3d e = t_cross * b_from_a.block<3, 3>(0, 0);  // x_b^T E x_a = 0
  std::vector<double> errors;
  for (int i : inliers) {
    if (bearings_a[i].z() <= 0 || bearings_b[i].z() <= 0) continue;
    const Eigen::Vector3d xa = bearings_a[i] / bearings_a[i].z(), xb = bearings_b[i] / bearings_b[i].z();
    const Eigen::Vector3d ea = e * xa, eb = e.transpose() * xb;
    const double denominator = ea.head<2>().squaredNorm() + eb.head<2>().squaredNorm();
    if (denominator <= 0) continue;
    errors.push_back(std::abs(xb.dot(ea)) / std::sqrt(denominator));
  }
  return errors;
}

}  // namespace

double RelativePoseResult::ParallaxRatio() const {
  return median_epipolar_error_px > 0 ? median_parallax_px / median_epipolar_error_px : 0.0;
}

double RelativePoseResult::HomographyRatio() const {
  return p90_epipolar_error_px > 0 ? p90_homography_error_px / p90_epipolar_error_px : 0.0;
}

RelativePoseResult EstimateRelativePose(const std::vector<Eigen::Vector3d>& rays_a,
                                        const std::vector<Eigen::Vector3d>& rays_b,
                                        RelativePoseSolver solver,
                                        const RansacOptions& options) {
  RelativePoseResult result;
  result.num_correspondences = static_cast<int>(std::min(rays_a.size(), rays_b.size()));
  if (Status valid = options.Validate(); !valid.ok()) {
    result.failure = valid.message();
    return result;
  }
  if (rays_a.size() != rays_b.size()) {
    result.failure =
        "got " + std::to_string(rays_a.size()) + " rays in view a and " + std::to_string(rays_b.size()) + " in view b";
    return result;
  }
  if (result.num_correspondences < kMinRelativePoseCorrespondences) {
    result.failure = std::to_string(result.num_correspondences) + " correspondences, need at least " +
                     std::to_string(kMinRelativePoseCorrespondences);
    return result;
  }
  // OpenGV's view 1 is b and view 2 is a, so that its (R12, t12) = b_from_a directly:
  // p_in_1 = R12 p_in_2 + t12.
  opengv::bearingVectors_t bearings_b, bearings_a;
  for (int i = 0; i < result.num_correspondences; ++i) {
    bearings_b.push_back(rays_b[i].normalized());
    bearings_a.push_back(rays_a[i].normalized());
  }
  opengv::relative_pose::CentralRelativeAdapter adapter(bearings_b, bearings_a);
  const double angle = options.MaxErrorRad();
  // OpenGV scores a pair by (1 - cos) of the reprojection angle in each view, summed.
  const double threshold = 2.0 * (1.0 - std::cos(angle));
  auto problem = std::make_shared<CentralRelativePoseSacProblem>(adapter,
                                                                 solver == RelativePoseSolver::kFivePoint
                                                                     ? CentralRelativePoseSacProblem::STEWENIUS
                                                                     : CentralRelativePoseSacProblem::EIGHTPT,
                                                                 /*randomSeed=*/false);
  opengv::transformation_t model;
  std::vector<int> inliers;
  if (!internal::RunRansac(problem, threshold, options, &model, &inliers, /*refine=*/true) ||
      inliers.size() < kMinRelativePoseCorrespondences) {
    result.failure = "no relative pose fits " + std::to_string(kMinRelativePoseCorrespondences) + " or more of " +
                     std::to_string(result.num_correspondences) + " correspondences";
    return result;
  }
  const Eigen::Matrix3d rotation = model.block<3, 3>(0, 0);
  Eigen::Vector3d translation = model.col(3);
  if (translation.norm() > 0) translation.normalize();
  result.b_from_a = Rigid3::FromMatrix(rotation, translation);
  result.inliers = inliers;

  // Parallax: what the best pure rotation (least squares over the inliers) leaves unexplained.
  // Measured against that rotation, not the five-point one: with no translation the essential
  // matrix is degenerate and its rotation can be off by the parallax it then "explains".
  const opengv::rotation_t best_rotation = opengv::relative_pose::rotationOnly(adapter, inliers);
  std::vector<double> parallax;
  parallax.reserve(inliers.size());
  for (int i : inliers) parallax.push_back(AngleBetween(bearings_b[i], best_rotation * bearings_a[i]));
  result.median_parallax_px = options.focal_px * std::tan(Median(parallax));
  const std::vector<double> sampson = SampsonErrors(bearings_b, bearings_a, model, inliers);
  result.median_epipolar_error_px = options.focal_px * Median(sampson);
  result.p90_epipolar_error_px = options.focal_px * Percentile(sampson, 0.9);

  auto rotation_problem = std::make_shared<RotationOnlySacProblem>(adapter, /*randomSeed=*/false);
  opengv::rotation_t rotation_only;
  std::vector<int> rotation_inliers;
  if (internal::RunRansac(rotation_problem, 1.0 - std::cos(2.0 * angle), options, &rotation_only, &rotation_inliers)) {
    result.rotation_only_inliers = static_cast<int>(rotation_inliers.size());
  }
  // The homography's threshold follows the matches' own noise (5x the median Sampson error,
  // within [0.5 px, max_error_px]): at the RANSAC threshold alone, a low-resolution view of a
  // deep scene would pass for a plane.
  const double homography_threshold_px =
      std::clamp(5.0 * result.median_epipolar_error_px, std::min(0.5, options.max_error_px), options.max_error_px);
  FitHomography(rays_a,
                rays_b,
                inliers,
                options.focal_px,
                options.max_error_px,
                homography_threshold_px,
                &result.homography_inlier_fraction,
                &result.p90_homography_error_px);
  result.success = true;
  return result;
}

}  // namespace px::calib
