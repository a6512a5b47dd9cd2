#include "pipeline/depth/neighbour_views.h"

#include <algorithm>
#include <limits>

namespace px::depth {

std::vector<int> ChooseNeighbourViews(
    const std::vector<View>& views, int reference, const std::vector<int>& candidates, int count, int num_spread) {
  const int wanted = std::min(count, static_cast<int>(candidates.size()));
  const int num_nearest = wanted - std::clamp(num_spread, 0, wanted);
  std::vector<int> chosen(candidates.begin(), candidates.begin() + num_nearest);
  // Distance of every remaining candidate to the nearest chosen centre (the reference included).
  std::vector<double> gap(candidates.size(), std::numeric_limits<double>::infinity());
  std::vector<char> taken(candidates.size(), 0);
  const auto shrink_gaps = [&](int view) {
    const Eigen::Vector3d centre = CameraCentre(views[view].cam_from_world);
    for (size_t i = 0; i < candidates.size(); ++i) {
      gap[i] = std::min(gap[i], (CameraCentre(views[candidates[i]].cam_from_world) - centre).norm());
    }
  };
  shrink_gaps(reference);
  for (int i = 0; i < num_nearest; ++i) {
    taken[i] = 1;
    shrink_gaps(candidates[i]);
  }
  while (static_cast<int>(chosen.size()) < wanted) {
    int best = -1;
    for (size_t i = 0; i < candidates.size(); ++i) {
      if (!taken[i] && (best < 0 || gap[i] > gap[best])) best = static_cast<int>(i);
    }
    taken[best] = 1;
    chosen.push_back(candidates[best]);
    shrink_gaps(candidates[best]);
  }
  return chosen;
}

}  // namespace px::depth
