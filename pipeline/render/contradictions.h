// Which views contradict which surfaces (ALGORITHM.md section 1, "Contradictions"). A texel's
// surface (either layer, at its segment's plane) is contradicted by another view when that view,
// along its own ray through the surface's point, sees only surfaces clearly farther (free space
// where the texel says something is) and of another colour. A subject that moved between shots,
// a sliver of wrong depth and a silhouette drawn too wide are all contradicted by the views that
// see past them; a surface that another view cannot see because something nearer hides it is
// not (that view has no say), so true disocclusions keep their surfaces. Computed once per scene.
#pragma once

#include <vector>

#include "pipeline/render/consistent_blend_options.h"
#include "pipeline/render/layered_scene.h"

namespace px::render {

// Fills each view's contradicted masks and neighbour tables (SceneView::contradicted,
// neighbours, neighbour_bit, SceneSegment::contradicted) against the views that can share a
// pixel's slots with it (`slot_neighbours`, ViewMesh::SlotNeighbours), the nearest
// options.max_neighbours of them. Returns the number of contradicted texel layers.
long FindContradictions(const ConsistentBlendOptions& options,
                        const std::vector<std::vector<int>>& slot_neighbours,
                        std::vector<SceneView>* views);

}  // namespace px::render
