// The mean matching cost of a plane over one segment, read from the plane-sweep cost volume: at
// each pixel the cost at the plane's fractional position, interpolated by the parabola through
// the three nearest planes (linear interpolation would put every minimum on a plane of the
// sweep and pull plane fits towards whole planes; the parabola is the sub-plane model of
// select_planes.h). Scores candidate planes for unfitted segments (segment_planes.h) and for
// segment-level PatchMatch (refine_segment_planes.h).
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "pipeline/depth/cost_volume.h"
#include "pipeline/depth/segment_planes.h"

namespace px::depth {

class VolumePlaneCost {
 public:
  // `slices` (one CV_32F cost per plane, at least 2; with 2 the cost is linear between them) and `segment_pixels`
  // (SegmentPixels: pixel indices y * cols + x) are borrowed and must outlive this object.
  VolumePlaneCost(const std::vector<cv::Mat>& slices,
                  const InverseDepthPlanes& planes,
                  const std::vector<std::vector<int>>& segment_pixels);

  // Lower is better; a pixel whose plane leaves the swept range counts kNoDataCost.
  double operator()(int segment, const InversePlane& plane) const;

 private:
  const std::vector<cv::Mat>& slices_;
  InverseDepthPlanes planes_;
  const std::vector<std::vector<int>>& segment_pixels_;
};

}  // namespace px::depth
