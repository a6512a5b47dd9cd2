// The plane-sweep cost volume of one reference view: for each fronto-parallel plane (uniform in
// inverse depth), every neighbour is warped into the reference view by the plane's homography
// and compared with windowed ZNCC; per pixel the best half of the neighbours' costs is averaged
// (a point occluded in some neighbours is still matched in the others) and each slice is
// aggregated edge-aware with a guided filter guided by the reference image.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "pipeline/depth/working_view.h"

namespace px::depth {

// Planes p = 0 .. count - 1 from the far end (p = 0) to the near end, uniform in 1 / z.
struct InverseDepthPlanes {
  double far_inverse_m = 0;
  double step_inverse_m = 0;
  int count = 0;
  double InverseDepth(double plane) const { return far_inverse_m + plane * step_inverse_m; }
  double PlaneOf(double inverse_depth_m) const { return (inverse_depth_m - far_inverse_m) / step_inverse_m; }
};

// count >= 2 planes over [min_depth_m, max_depth_m].
InverseDepthPlanes MakeInverseDepthPlanes(double min_depth_m, double max_depth_m, int count);

struct CostVolumeOptions {
  int window_radius_px = 3;           // ZNCC window (2r+1)^2
  double min_texture_stddev = 0.004;  // textureless windows cost kNeutralCost
  int filter_radius_px = 4;           // guided filter; 0 = no aggregation
  double filter_eps = 1e-4;
};

struct CostVolume {
  std::vector<cv::Mat> slices;  // one CV_32F cost per plane, in [0, kNoDataCost]
  // CV_8U, 255 where the neighbours sampled at least half of the farthest quarter of the planes.
  // A pixel they reach only at near depths (the border strip a turned hand-held view sees past
  // the others, which its parallax brings into them only at near planes) has its best match
  // among the wrong depths: a repeating texture such as blinds finds one there. Near planes left
  // unsampled (parallax carrying a border pixel out of the neighbour) leave the far ones, where
  // what a border shows usually lies.
  cv::Mat sampled;
  // CV_32F, per pixel the lowest best-half cost over the planes before the guided filter: how
  // well the pixel's own window matches the neighbours at its best depth, whatever the
  // aggregation (the depth stage's check for views of another scene reads it).
  cv::Mat best_unfiltered_cost;
  // CV_32F, per pixel the mean of those costs over every 4th plane where the neighbours were
  // sampled (kNoDataCost where never): what the pixel's window costs at depths that are not its
  // own, against which its best cost tells a match from a view of another scene.
  cv::Mat typical_unfiltered_cost;
};

// Planes are processed in parallel (cv::parallel_for_), each worker with its own buffers.
CostVolume BuildCostVolume(const WorkingView& ref,
                           const std::vector<const WorkingView*>& neighbours,
                           const InverseDepthPlanes& planes,
                           const CostVolumeOptions& options);

}  // namespace px::depth
