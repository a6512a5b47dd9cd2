#include "eval/calib/pose_alignment.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace px::eval {
namespace {

Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& m) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1 : 1;
  return svd.matrixU() * d * svd.matrixV().transpose();
}

double MedianNearestNeighbour(const std::vector<Eigen::Vector3d>& centres) {
  std::vector<double> nearest;
  for (size_t i = 0; i < centres.size(); ++i) {
    double best = std::numeric_limits<double>::infinity();
    for (size_t j = 0; j < centres.size(); ++j) {
      if (i != j) best = std::min(best, (centres[i] - centres[j]).norm());
    }
    if (std::isfinite(best)) nearest.push_back(best);
  }
  if (nearest.empty()) return 0;
  std::nth_element(nearest.begin(), nearest.begin() + nearest.size() / 2, nearest.end());
  return nearest[nearest.size() / 2];
}

}  // namespace

double PoseErrors::Mean(const std::vector<double>& values) {
  if (values.empty()) return 0;
  double sum = 0;
  for (double v : values) sum += v;
  return sum / static_cast<double>(values.size());
}

double PoseErrors::Max(const std::vector<double>& values) {
  double best = 0;
  for (double v : values) best = std::max(best, v);
  return best;
}

Similarity AlignPoses(const std::vector<Rigid3>& estimated, const std::vector<Rigid3>& reference) {
  Similarity s;
  const size_t n = std::min(estimated.size(), reference.size());
  if (n == 0) return s;
  // World rotation: a point p_est maps to R p_est; for each view, R_ref = R_est R^T, so
  // R = R_ref^T R_est ... averaged (chordal mean: the rotation nearest the summed matrices).
  Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < n; ++i) sum += reference[i].RotationMatrix().transpose() * estimated[i].RotationMatrix();
  s.rotation = NearestRotation(sum);
  // Scale and translation: least squares of |s R c_est + t - c_ref|^2.
  Eigen::Vector3d mean_est = Eigen::Vector3d::Zero(), mean_ref = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> est(n), ref(n);
  for (size_t i = 0; i < n; ++i) {
    est[i] = s.rotation * CameraCentre(estimated[i]);
    ref[i] = CameraCentre(reference[i]);
    mean_est += est[i] / static_cast<double>(n);
    mean_ref += ref[i] / static_cast<double>(n);
  }
  double numerator = 0, denominator = 0;
  for (size_t i = 0; i < n; ++i) {
    numerator += (est[i] - mean_est).dot(ref[i] - mean_ref);
    denominator += (est[i] - mean_est).squaredNorm();
  }
  s.scale = denominator > 0 && numerator > 0 ? numerator / denominator : 1.0;
  s.translation = mean_ref - s.scale * mean_est;
  return s;
}

StatusOr<PoseErrors> ComparePoses(const std::vector<Rigid3>& estimated,
                                  const std::vector<Rigid3>& reference,
                                  const std::vector<double>& estimated_focal_px,
                                  const std::vector<double>& reference_focal_px) {
  if (estimated.size() != reference.size() || estimated.empty()) {
    return InvalidArgumentError("pose comparison: " + std::to_string(estimated.size()) + " estimated and " +
                                std::to_string(reference.size()) + " reference poses");
  }
  if (estimated_focal_px.size() != reference_focal_px.size() ||
      (!estimated_focal_px.empty() && estimated_focal_px.size() != estimated.size())) {
    return InvalidArgumentError("pose comparison: " + std::to_string(estimated_focal_px.size()) + " estimated and " +
                                std::to_string(reference_focal_px.size()) + " reference focal lengths for " +
                                std::to_string(estimated.size()) + " views");
  }
  PoseErrors errors;
  errors.alignment = AlignPoses(estimated, reference);
  std::vector<Eigen::Vector3d> reference_centres;
  for (const Rigid3& pose : reference) reference_centres.push_back(CameraCentre(pose));
  errors.reference_baseline = MedianNearestNeighbour(reference_centres);
  const Eigen::Matrix3d& r = errors.alignment.rotation;
  for (size_t i = 0; i < estimated.size(); ++i) {
    // The estimate in the reference world: R_cam' = R_cam R^T, centre' = s R c + t.
    const Eigen::Matrix3d aligned = estimated[i].RotationMatrix() * r.transpose();
    const Eigen::AngleAxisd difference(aligned * reference[i].RotationMatrix().transpose());
    errors.rotation_deg.push_back(std::abs(difference.angle()) * 180.0 / M_PI);
    const double distance = (errors.alignment.Apply(CameraCentre(estimated[i])) - reference_centres[i]).norm();
    errors.centre_relative.push_back(errors.reference_baseline > 0 ? distance / errors.reference_baseline : 0.0);
    if (!estimated_focal_px.empty()) {
      errors.focal_relative.push_back(std::abs(estimated_focal_px[i] / reference_focal_px[i] - 1.0));
    }
  }
  return errors;
}

StatusOr<PoseErrors> CompareRigs(const RigCalibration& estimate, const RigCalibration& reference) {
  if (estimate.NumViews() != reference.NumViews()) {
    return InvalidArgumentError("compare rigs: '" + estimate.rig_name + "' has " + std::to_string(estimate.NumViews()) +
                                " lenses, '" + reference.rig_name + "' " + std::to_string(reference.NumViews()));
  }
  std::vector<Rigid3> estimated_poses, reference_poses;
  std::vector<double> estimated_focal, reference_focal;
  for (int i = 0; i < reference.NumViews(); ++i) {
    estimated_poses.push_back(estimate.lenses[i].cam_from_rig);
    reference_poses.push_back(reference.lenses[i].cam_from_rig);
    estimated_focal.push_back(estimate.lenses[i].camera.fx);
    reference_focal.push_back(reference.lenses[i].camera.fx);
  }
  return ComparePoses(estimated_poses, reference_poses, estimated_focal, reference_focal);
}

}  // namespace px::eval
