// Which views a reference view is matched against. The nearest camera centres see the scene
// most alike (small occlusions, similar shading), the farthest ones pin depth down best (one
// plane step moves them most): a light field's 9x9 grid has 80 candidates, but the best-half
// aggregation holds at most 16, and the 16 nearest all lie within two grid steps.
#pragma once

#include <vector>

#include "pipeline/core/view.h"

namespace px::depth {

// Up to `count` of `candidates` (indices into views, nearest to the reference first): the first
// count - num_spread as they come, then num_spread more by farthest-point sampling of camera
// centres (each the candidate farthest from the reference and every view already chosen; ties
// to the nearer one), which spreads them over the widest baselines and every direction.
// num_spread is clamped to [0, count].
std::vector<int> ChooseNeighbourViews(
    const std::vector<View>& views, int reference, const std::vector<int>& candidates, int count, int num_spread);

}  // namespace px::depth
