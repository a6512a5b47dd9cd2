// Runs an OpenGV sample-consensus problem with our seed (OpenGV seeds from the clock unless
// told otherwise, and then always from 12345). Internal to pipeline/calib.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <opengv/sac/Ransac.hpp>
#include <vector>

#include "pipeline/calib/ransac_options.h"

namespace px::calib::internal {

// Replaces the problem's generator by one seeded with `seed` (its members are public).
template <typename Problem>
void SeedProblem(Problem* problem, uint64_t seed) {
  problem->rng_alg_.seed(static_cast<std::mt19937::result_type>(seed ^ (seed >> 32)));
  problem->rng_gen_ = std::make_shared<std::function<int()>>(std::bind(*problem->rng_dist_, problem->rng_alg_));
}

// Runs RANSAC; false when no model was found. `threshold` is in the problem's own distance unit.
// With `refine`, the model is then re-estimated (nonlinearly) on all its inliers and kept when
// it explains at least as many.
template <typename Problem>
bool RunRansac(std::shared_ptr<Problem> problem,
               double threshold,
               const RansacOptions& options,
               typename Problem::model_t* model,
               std::vector<int>* inliers,
               bool refine = false) {
  SeedProblem(problem.get(), options.seed);
  opengv::sac::Ransac<Problem> ransac(options.max_iterations, threshold, options.confidence);
  ransac.sac_model_ = problem;
  if (!ransac.computeModel(0)) return false;
  *model = ransac.model_coefficients_;
  *inliers = ransac.inliers_;
  if (!refine) return true;
  typename Problem::model_t refined;
  problem->optimizeModelCoefficients(*inliers, *model, refined);
  std::vector<int> refined_inliers;
  problem->selectWithinDistance(refined, threshold, refined_inliers);
  if (refined.allFinite() && refined_inliers.size() >= inliers->size()) {
    *model = refined;
    *inliers = std::move(refined_inliers);
  }
  return true;
}

}  // namespace px::calib::internal
