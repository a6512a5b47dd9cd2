#include "pipeline/depth/volume_plane_cost.h"

#include <algorithm>
#include <cmath>

#include "pipeline/core/check.h"
#include "pipeline/depth/zncc_cost.h"

namespace px::depth {

VolumePlaneCost::VolumePlaneCost(const std::vector<cv::Mat>& slices,
                                 const InverseDepthPlanes& planes,
                                 const std::vector<std::vector<int>>& segment_pixels)
    : slices_(slices), planes_(planes), segment_pixels_(segment_pixels) {
  PX_CHECK(slices.size() >= 2 && static_cast<int>(slices.size()) == planes.count) << "a volume of 2 planes or more";
}

double VolumePlaneCost::operator()(int segment, const InversePlane& plane) const {
  const std::vector<int>& pixels = segment_pixels_[segment];
  const int cols = slices_[0].cols, last = planes_.count - 1;
  double sum = 0;
  for (int index : pixels) {
    const int x = index % cols, y = index / cols;
    const double p = planes_.PlaneOf(plane.At(x, y));
    if (!(p >= 0 && p <= last)) {
      sum += kNoDataCost;
      continue;
    }
    if (last < 2) {  // two planes: a line
      sum += (1 - p) * slices_[0].at<float>(y, x) + p * slices_[1].at<float>(y, x);
      continue;
    }
    const int centre = std::clamp(static_cast<int>(std::lround(p)), 1, last - 1);
    const double t = p - centre;
    const double before = slices_[centre - 1].at<float>(y, x), at = slices_[centre].at<float>(y, x),
                 after = slices_[centre + 1].at<float>(y, x);
    sum += at + 0.5 * t * (after - before) + 0.5 * t * t * (after - 2 * at + before);
  }
  return sum / std::max<size_t>(pixels.size(), 1);
}

}  // namespace px::depth
