// The largest aperture a path's endpoint allows (paper 4.3): an aperture is judged by its four
// corner viewpoints (the corners of the aperture's square, in the camera's image plane), and is
// valid while all four are valid viewpoints. Adaptive: double while valid, then halve.
#pragma once

#include "pipeline/core/status.h"
#include "pipeline/direct/coverage_probe.h"
#include "pipeline/direct/scene_geometry.h"
#include "pipeline/direct/valid_viewpoints.h"

namespace px::direct {

struct ApertureResult {
  double aperture_m = 0;        // largest valid diameter found, 0 when even a tiny one is not
  double worst_hole_score = 0;  // max H(V) over the corners at that aperture
  int probes = 0;
};

// Searches (0, max_aperture_m] to `precision_m`, starting at max_aperture_m / 16.
StatusOr<ApertureResult> LargestValidAperture(const Framing& endpoint,
                                              const SceneGeometry& scene,
                                              CoverageProbe* probe,
                                              double max_aperture_m,
                                              double precision_m);

// The four corner viewpoints of an aperture of diameter `aperture_m` around `endpoint`.
std::vector<Framing> ApertureCorners(const Framing& endpoint, double aperture_m);

}  // namespace px::direct
