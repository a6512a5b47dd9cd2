// Options for choosing the virtual camera's path (paper section 4.2).
#pragma once

#include <string>

#include "pipeline/core/status.h"

namespace px {

struct DirectOptions {
  // The camera move from the taxonomy (paper table 1): "auto" lets the scene decide,
  // "establishing_dolly" forces a sideways dolly across the viewpoints.
  std::string move = "auto";
  double duration_s = 5.0;  // clip length in seconds, (0, 60]
  double fps = 30.0;        // frames per second, (0, 240]
  // Establishing dolly: aim every keyframe at the median scene depth on the mean view axis
  // (the paper points at the scene centroid, so that depth stays still on screen while nearer
  // things move one way and farther things the other). false: look straight ahead.
  bool converge = true;

  Status Validate() const;
};

// The moves PlanCameraPath knows, for Validate and help texts.
bool IsKnownMove(const std::string& move);

}  // namespace px
