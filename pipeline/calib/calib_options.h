// Options for stage 2 (calibrated, undistorted views). Per-shot refinement will add fields here.
#pragma once

#include "pipeline/core/status.h"

namespace px {

struct CalibOptions {
  enum class Interpolation {
    kLinear,  // bilinear: fast, slightly soft; enough for depth and rendering
    kCubic,   // bicubic: keeps a little more detail, about twice the cost
  };
  // How undistortion resamples the tile.
  Interpolation interpolation = Interpolation::kLinear;

  // OK when every field holds one of its allowed values.
  Status Validate() const;
};

}  // namespace px
