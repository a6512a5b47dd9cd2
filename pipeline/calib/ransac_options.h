// Options shared by the robust (RANSAC) estimators of per-shot calibration and SfM.
#pragma once

#include <cstdint>

#include "pipeline/core/status.h"

namespace px::calib {

struct RansacOptions {
  // A correspondence is an inlier when its reprojection error is below this, in pixels at
  // `focal_px` (the estimators work on rays and convert), (0, 100].
  double max_error_px = 2.0;
  // The focal length that converts pixels to angles, (0, 1e6] pixels.
  double focal_px = 500.0;
  // Hypotheses at most, [1, 100000]; RANSAC stops earlier once `confidence` is reached.
  int max_iterations = 2000;
  // Probability of having drawn one outlier-free sample when stopping early, (0, 1).
  double confidence = 0.9999;
  // Seeds the sampling: the same seed and input give the same result.
  uint64_t seed = 1;

  Status Validate() const;
  // The angle of `max_error_px` at `focal_px`, in radians.
  double MaxErrorRad() const;
};

}  // namespace px::calib
