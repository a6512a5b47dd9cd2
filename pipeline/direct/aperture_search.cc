#include "pipeline/direct/aperture_search.h"

#include <algorithm>
#include <optional>

namespace px::direct {

std::vector<Framing> ApertureCorners(const Framing& endpoint, double aperture_m) {
  const Eigen::Matrix3d world_from_cam = endpoint.cam_from_world.RotationMatrix().transpose();
  const Eigen::Vector3d right = world_from_cam.col(0), down = world_from_cam.col(1);
  std::vector<Framing> corners;
  for (double sx : {-0.5, 0.5}) {
    for (double sy : {-0.5, 0.5}) {
      Framing corner = endpoint;
      corner.centre_in_world = endpoint.centre_in_world + aperture_m * (sx * right + sy * down);
      corner.cam_from_world =
          Rigid3(endpoint.cam_from_world.rotation, -(endpoint.cam_from_world.rotation * corner.centre_in_world));
      corners.push_back(corner);
    }
  }
  return corners;
}

StatusOr<ApertureResult> LargestValidAperture(const Framing& endpoint,
                                              const SceneGeometry& scene,
                                              CoverageProbe* probe,
                                              double max_aperture_m,
                                              double precision_m) {
  ApertureResult result;
  const CameraModel camera = scene.OutputWithFocal(endpoint.focal_px);
  // Worst corner H at an aperture; stops at the first invalid corner.
  const auto worst = [&](double aperture) -> StatusOr<double> {
    double max_score = 0;
    for (const Framing& corner : ApertureCorners(endpoint, aperture)) {
      PX_ASSIGN_OR_RETURN(double score, probe->HoleScore(camera, corner.cam_from_world));
      ++result.probes;
      max_score = std::max(max_score, score);
      if (max_score >= probe->valid_hole_score()) break;
    }
    return max_score;
  };
  double lo = 0, lo_score = 0;
  std::optional<double> hi;
  double step = max_aperture_m / 16;
  while (!hi && lo < max_aperture_m) {
    const double next = std::min(max_aperture_m, lo + step);
    PX_ASSIGN_OR_RETURN(double score, worst(next));
    if (score < probe->valid_hole_score()) {
      lo = next;
      lo_score = score;
      step *= 2;
    } else {
      hi = next;
    }
  }
  while (hi && *hi - lo > precision_m) {
    const double mid = 0.5 * (lo + *hi);
    PX_ASSIGN_OR_RETURN(double score, worst(mid));
    if (score < probe->valid_hole_score()) {
      lo = mid;
      lo_score = score;
    } else {
      hi = mid;
    }
  }
  result.aperture_m = lo;
  result.worst_hole_score = lo_score;
  return result;
}

}  // namespace px::direct
