#include "pipeline/calib/absolute_pose.h"

#include <cmath>
#include <memory>
#include <opengv/absolute_pose/CentralAbsoluteAdapter.hpp>
#include <opengv/sac_problems/absolute_pose/AbsolutePoseSacProblem.hpp>

#include "pipeline/calib/opengv_ransac.h"

namespace px::calib {
namespace {

using opengv::sac_problems::absolute_pose::AbsolutePoseSacProblem;

constexpr int kMinAbsolutePoseCorrespondences = 6;

}  // namespace

AbsolutePoseResult EstimateAbsolutePose(const std::vector<Eigen::Vector3d>& rays,
                                        const std::vector<Eigen::Vector3d>& points_in_world,
                                        AbsolutePoseSolver solver,
                                        const RansacOptions& options) {
  AbsolutePoseResult result;
  if (Status valid = options.Validate(); !valid.ok()) {
    result.failure = valid.message();
    return result;
  }
  if (rays.size() != points_in_world.size()) {
    result.failure =
        "got " + std::to_string(rays.size()) + " rays and " + std::to_string(points_in_world.size()) + " points";
    return result;
  }
  if (rays.size() < kMinAbsolutePoseCorrespondences) {
    result.failure = std::to_string(rays.size()) + " 2D-3D correspondences, need at least " +
                     std::to_string(kMinAbsolutePoseCorrespondences);
    return result;
  }
  opengv::bearingVectors_t bearings;
  opengv::points_t points;
  for (size_t i = 0; i < rays.size(); ++i) {
    bearings.push_back(rays[i].normalized());
    points.push_back(points_in_world[i]);
  }
  opengv::absolute_pose::CentralAbsoluteAdapter adapter(bearings, points);
  auto problem = std::make_shared<AbsolutePoseSacProblem>(
      adapter,
      solver == AbsolutePoseSolver::kP3p ? AbsolutePoseSacProblem::KNEIP : AbsolutePoseSacProblem::EPNP,
      /*randomSeed=*/false);
  // OpenGV scores a correspondence by 1 - cos of the angle between its ray and the reprojection.
  const double threshold = 1.0 - std::cos(options.MaxErrorRad());
  opengv::transformation_t model;
  std::vector<int> inliers;
  if (!internal::RunRansac(problem, threshold, options, &model, &inliers, /*refine=*/true) ||
      static_cast<int>(inliers.size()) < kMinAbsolutePoseCorrespondences) {
    result.failure = "no pose fits " + std::to_string(kMinAbsolutePoseCorrespondences) + " or more of " +
                     std::to_string(rays.size()) + " 2D-3D correspondences";
    return result;
  }
  // OpenGV's model is the camera's pose in the world: p_in_world = R p_in_cam + t.
  const Rigid3 world_from_cam = Rigid3::FromMatrix(model.block<3, 3>(0, 0), model.col(3));
  result.cam_from_world = world_from_cam.Inverse();
  result.inliers = inliers;
  result.success = true;
  return result;
}

}  // namespace px::calib
