#include "pipeline/calib/bundle_adjustment.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <glog/logging.h>

#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <memory>

#include "pipeline/calib/reprojection_cost.h"
#include "pipeline/core/log.h"
#include "pipeline/core/stage_clock.h"

namespace px::calib {
namespace {

// Ceres logs through glog, which, never initialised, prints a banner and every routine warning
// (a Levenberg-Marquardt step whose Cholesky factorisation failed, retried with more damping)
// on the user's terminal. Once per process: glog initialised to stderr, errors only.
void QuietCeresLogging() {
  static const bool quiet = [] {
    FLAGS_logtostderr = true;
    FLAGS_minloglevel = google::GLOG_ERROR;
    if (!google::IsGoogleLoggingInitialized()) google::InitGoogleLogging("parallax");
    return true;
  }();
  (void)quiet;
}

struct PosePriorCost {
  PosePriorCost(const Rigid3& prior, double rotation_sigma_rad, double centre_sigma_m)
      : centre(CameraCentre(prior)),
        rotation_weight(rotation_sigma_rad > 0 ? 1.0 / rotation_sigma_rad : 0.0),
        centre_weight(centre_sigma_m > 0 ? 1.0 / centre_sigma_m : 0.0) {
    // Ceres quaternions are (w, x, y, z); store the prior's conjugate.
    inverse[0] = prior.rotation.w();
    inverse[1] = -prior.rotation.x();
    inverse[2] = -prior.rotation.y();
    inverse[3] = -prior.rotation.z();
  }

  template <typename T>
  bool operator()(const T* rotation, const T* camera_centre, T* residual) const {
    const T prior_inverse[4] = {T(inverse[0]), T(inverse[1]), T(inverse[2]), T(inverse[3])};
    T delta[4];
    ceres::QuaternionProduct(prior_inverse, rotation, delta);
    T angle_axis[3];
    ceres::QuaternionToAngleAxis(delta, angle_axis);
    for (int i = 0; i < 3; ++i) {
      residual[i] = T(rotation_weight) * angle_axis[i];
      residual[3 + i] = T(centre_weight) * (camera_centre[i] - T(centre[i]));
    }
    return true;
  }

  double inverse[4];
  Eigen::Vector3d centre;
  double rotation_weight, centre_weight;
};

struct IntrinsicsPriorCost {
  IntrinsicsPriorCost(const BaPrior& prior)
      : focal(prior.focal_px),
        cx(prior.cx),
        cy(prior.cy),
        focal_weight(prior.focal_sigma_relative > 0 && prior.focal_px > 0
                         ? 1.0 / (prior.focal_sigma_relative * prior.focal_px)
                         : 0.0),
        principal_weight(prior.principal_point_sigma_px > 0 ? 1.0 / prior.principal_point_sigma_px : 0.0) {}

  template <typename T>
  bool operator()(const T* intrinsics, T* residual) const {
    residual[0] = T(focal_weight) * (intrinsics[kFocal] - T(focal));
    residual[1] = T(principal_weight) * (intrinsics[kCx] - T(cx));
    residual[2] = T(principal_weight) * (intrinsics[kCy] - T(cy));
    return true;
  }

  double focal, cx, cy, focal_weight, principal_weight;
};

// Keeps |c_a - c_b| at its initial value (fixes the scale of an SfM).
struct DistanceCost {
  DistanceCost(double distance, double weight) : distance(distance), weight(weight) {}
  template <typename T>
  bool operator()(const T* a, const T* b, T* residual) const {
    const T dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
    residual[0] = T(weight) * (ceres::sqrt(dx * dx + dy * dy + dz * dz + T(1e-30)) - T(distance));
    return true;
  }
  double distance, weight;
};

struct CameraBlocks {
  double rotation[4];  // w, x, y, z
  double centre[3];
};

bool SameIntrinsics(const CameraModel& a, const CameraModel& b) {
  return a.width == b.width && a.height == b.height && a.fx == b.fx && a.fy == b.fy && a.cx == b.cx && a.cy == b.cy &&
         a.distortion == b.distortion;
}

}  // namespace

Status BundleAdjustmentOptions::Validate() const {
  if (!(loss_scale_px > 0 && loss_scale_px <= 100)) {
    return InvalidArgumentError("bundle adjustment: loss_scale_px = " + std::to_string(loss_scale_px) +
                                " is outside (0, 100]");
  }
  if (!(function_tolerance > 0 && function_tolerance < 1)) {
    return InvalidArgumentError("bundle adjustment: function_tolerance = " + std::to_string(function_tolerance) +
                                " is outside (0, 1)");
  }
  if (max_iterations < 1 || max_iterations > 1000) {
    return InvalidArgumentError("bundle adjustment: max_iterations = " + std::to_string(max_iterations) +
                                " is outside [1, 1000]");
  }
  if (num_threads < 1 || num_threads > 64) {
    return InvalidArgumentError("bundle adjustment: num_threads = " + std::to_string(num_threads) +
                                " is outside [1, 64]");
  }
  return OkStatus();
}

std::vector<double> ReprojectionErrors(const BaProblem& problem) {
  std::vector<double> errors;
  errors.reserve(problem.observations.size());
  for (const BaObservation& observation : problem.observations) {
    const BaCamera& camera = problem.cameras[observation.camera];
    Eigen::Vector2d projected;
    if (!camera.camera.Project(camera.cam_from_world * problem.points[observation.point], &projected)) {
      errors.push_back(std::numeric_limits<double>::infinity());
    } else {
      errors.push_back((projected - observation.pixel).norm());
    }
  }
  return errors;
}

double ReprojectionRms(const BaProblem& problem) {
  double sum = 0;
  int count = 0;
  for (double error : ReprojectionErrors(problem)) {
    if (!std::isfinite(error)) continue;
    sum += error * error;
    ++count;
  }
  return count > 0 ? std::sqrt(sum / count) : 0.0;
}

StatusOr<BundleAdjustmentReport> BundleAdjust(BaProblem* problem,
                                              const std::vector<BaPrior>& priors,
                                              const BundleAdjustmentOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  PX_RETURN_IF_ERROR(options.Validate());
  const int num_cameras = static_cast<int>(problem->cameras.size());
  const int num_points = static_cast<int>(problem->points.size());
  for (size_t i = 0; i < problem->observations.size(); ++i) {
    const BaObservation& o = problem->observations[i];
    if (o.camera < 0 || o.camera >= num_cameras || o.point < 0 || o.point >= num_points) {
      return InvalidArgumentError("bundle adjustment: observation " + std::to_string(i) + " names camera " +
                                  std::to_string(o.camera) + " and point " + std::to_string(o.point) + " of " +
                                  std::to_string(num_cameras) + " and " + std::to_string(num_points));
    }
  }
  // One intrinsics block per group (or per camera without a group).
  std::vector<int> block_of_camera(num_cameras);
  std::vector<std::array<double, kIntrinsicsSize>> intrinsics;
  std::vector<int> block_owner;  // the camera whose model the block started from
  std::map<int, int> block_of_group;
  for (int c = 0; c < num_cameras; ++c) {
    const BaCamera& camera = problem->cameras[c];
    PX_RETURN_IF_ERROR(camera.camera.Validate().WithContext("bundle adjustment: camera " + std::to_string(c)));
    if (camera.intrinsics_group >= 0) {
      auto found = block_of_group.find(camera.intrinsics_group);
      if (found != block_of_group.end()) {
        if (!SameIntrinsics(problem->cameras[block_owner[found->second]].camera, camera.camera)) {
          return InvalidArgumentError("bundle adjustment: camera " + std::to_string(c) + " shares intrinsics group " +
                                      std::to_string(camera.intrinsics_group) + " but starts with other intrinsics");
        }
        block_of_camera[c] = found->second;
        continue;
      }
      block_of_group[camera.intrinsics_group] = static_cast<int>(intrinsics.size());
    }
    block_of_camera[c] = static_cast<int>(intrinsics.size());
    block_owner.push_back(c);
    const CameraModel& model = camera.camera;
    intrinsics.push_back({model.fx, model.cx, model.cy, model.distortion[0], model.distortion[1]});
  }
  std::vector<CameraBlocks> blocks(num_cameras);
  for (int c = 0; c < num_cameras; ++c) {
    const Rigid3& pose = problem->cameras[c].cam_from_world;
    const Eigen::Quaterniond q = pose.rotation.normalized();
    blocks[c].rotation[0] = q.w();
    blocks[c].rotation[1] = q.x();
    blocks[c].rotation[2] = q.y();
    blocks[c].rotation[3] = q.z();
    const Eigen::Vector3d centre = CameraCentre(pose);
    for (int k = 0; k < 3; ++k) blocks[c].centre[k] = centre[k];
  }

  BundleAdjustmentReport report;
  report.num_observations = static_cast<int>(problem->observations.size());
  report.initial_rms_px = ReprojectionRms(*problem);

  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem ceres_problem(problem_options);
  ceres::CauchyLoss loss(options.loss_scale_px);
  ceres::QuaternionManifold quaternion_manifold;
  for (const BaObservation& o : problem->observations) {
    auto* cost = new AnalyticReprojectionCost(
        ReprojectionTerms(o.pixel, problem->cameras[block_owner[block_of_camera[o.camera]]].camera));
    ceres_problem.AddResidualBlock(cost,
                                   &loss,
                                   blocks[o.camera].rotation,
                                   blocks[o.camera].centre,
                                   intrinsics[block_of_camera[o.camera]].data(),
                                   problem->points[o.point].data());
  }
  for (const BaPrior& prior : priors) {
    if (prior.camera < 0 || prior.camera >= num_cameras) {
      return InvalidArgumentError("bundle adjustment: a prior names camera " + std::to_string(prior.camera) + " of " +
                                  std::to_string(num_cameras));
    }
    CameraBlocks& camera = blocks[prior.camera];
    if (prior.rotation_sigma_deg > 0 || prior.centre_sigma_m > 0) {
      ceres_problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<PosePriorCost, 6, 4, 3>(
              new PosePriorCost(prior.cam_from_world, prior.rotation_sigma_deg * M_PI / 180.0, prior.centre_sigma_m)),
          nullptr,
          camera.rotation,
          camera.centre);
    }
    if (prior.focal_sigma_relative > 0 || prior.principal_point_sigma_px > 0) {
      ceres_problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<IntrinsicsPriorCost, 3, kIntrinsicsSize>(new IntrinsicsPriorCost(prior)),
          nullptr,
          intrinsics[block_of_camera[prior.camera]].data());
    }
  }
  const bool anchored = options.scale_anchor_a >= 0 && options.scale_anchor_b >= 0 &&
                        options.scale_anchor_a < num_cameras && options.scale_anchor_b < num_cameras &&
                        options.scale_anchor_a != options.scale_anchor_b;
  if (anchored) {
    const Eigen::Vector3d a(blocks[options.scale_anchor_a].centre), b(blocks[options.scale_anchor_b].centre);
    const double distance = (a - b).norm();
    if (distance > 0) {
      ceres_problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<DistanceCost, 1, 3, 3>(new DistanceCost(distance, 1e6 / distance)),
          nullptr,
          blocks[options.scale_anchor_a].centre,
          blocks[options.scale_anchor_b].centre);
    }
  }

  // What moves.
  for (int c = 0; c < num_cameras; ++c) {
    if (!ceres_problem.HasParameterBlock(blocks[c].rotation)) continue;
    ceres_problem.SetManifold(blocks[c].rotation, &quaternion_manifold);
    const bool pose_fixed = problem->cameras[c].pose_fixed || !options.refine_poses;
    if (pose_fixed) ceres_problem.SetParameterBlockConstant(blocks[c].rotation);
    if (pose_fixed || !options.refine_centres) ceres_problem.SetParameterBlockConstant(blocks[c].centre);
  }
  std::vector<int> constant_intrinsics;
  if (!options.refine_focal) constant_intrinsics.push_back(kFocal);
  if (!options.refine_principal_point) {
    constant_intrinsics.push_back(kCx);
    constant_intrinsics.push_back(kCy);
  }
  if (!options.refine_radial) {
    constant_intrinsics.push_back(kK1);
    constant_intrinsics.push_back(kK2);
  }
  std::unique_ptr<ceres::SubsetManifold> intrinsics_manifold;
  if (!constant_intrinsics.empty() && constant_intrinsics.size() < kIntrinsicsSize) {
    intrinsics_manifold = std::make_unique<ceres::SubsetManifold>(kIntrinsicsSize, constant_intrinsics);
  }
  for (auto& block : intrinsics) {
    if (!ceres_problem.HasParameterBlock(block.data())) continue;
    if (constant_intrinsics.size() == kIntrinsicsSize) {
      ceres_problem.SetParameterBlockConstant(block.data());
    } else if (intrinsics_manifold) {
      ceres_problem.SetManifold(block.data(), intrinsics_manifold.get());
    }
  }
  if (!options.refine_points) {
    for (Eigen::Vector3d& point : problem->points) {
      if (ceres_problem.HasParameterBlock(point.data())) ceres_problem.SetParameterBlockConstant(point.data());
    }
  }

  QuietCeresLogging();
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_SCHUR;
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.num_threads = options.num_threads;
  solver_options.logging_type = ceres::SILENT;
  solver_options.function_tolerance = options.function_tolerance;
  solver_options.parameter_tolerance = 1e-10;
  ceres::Solver::Summary summary;
  if (ceres_problem.NumResidualBlocks() > 0) ceres::Solve(solver_options, &ceres_problem, &summary);

  for (int c = 0; c < num_cameras; ++c) {
    const Eigen::Quaterniond q(
        blocks[c].rotation[0], blocks[c].rotation[1], blocks[c].rotation[2], blocks[c].rotation[3]);
    const Eigen::Vector3d centre(blocks[c].centre);
    BaCamera& camera = problem->cameras[c];
    if (!camera.pose_fixed) camera.cam_from_world = Rigid3(q, -(q.normalized() * centre));
    const auto& k = intrinsics[block_of_camera[c]];
    const double aspect = camera.camera.fy / camera.camera.fx;
    camera.camera.fx = k[kFocal];
    camera.camera.fy = k[kFocal] * aspect;
    camera.camera.cx = k[kCx];
    camera.camera.cy = k[kCy];
    camera.camera.distortion[0] = k[kK1];
    camera.camera.distortion[1] = k[kK2];
  }
  report.iterations = static_cast<int>(summary.iterations.size());
  report.converged = ceres_problem.NumResidualBlocks() == 0 || summary.termination_type == ceres::CONVERGENCE;
  report.message = ceres_problem.NumResidualBlocks() == 0 ? "nothing to adjust" : summary.message;
  report.final_rms_px = ReprojectionRms(*problem);
  report.ms = MsSince(start);
  Logger("calib")->debug(
      "bundle adjustment: {} cameras, {} points, {} observations, {} iterations, RMS {:.3f} -> {:.3f} px, {:.1f} ms "
      "({})",
      num_cameras,
      num_points,
      report.num_observations,
      report.iterations,
      report.initial_rms_px,
      report.final_rms_px,
      report.ms,
      summary.message);
  return report;
}

}  // namespace px::calib
