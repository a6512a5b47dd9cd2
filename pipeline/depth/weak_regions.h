// Unfitted segments that continue one plain surface take one plane.
//
// AssignUnfittedSegments settles each segment without confident pixels by itself, from whichever
// settled neighbour ties on matching cost and looks alike. Across a large plain surface (a wooden
// desk top, a wall) the planes then chain from segment to segment, and a plane fitted to a thin
// textured strip at the surface's edge carries its poorly constrained slope ever further: the
// surface's depth wanders from segment to segment, and its outline moves unevenly in a novel view.
// Here touching propagated segments alike in colour form weak regions; each region weighs the
// planes its members hold and its fitted neighbours hold by the matching cost summed over the
// whole region (its few textured pixels decide for all of it), and each member takes the best
// unless the cost over its own pixels says otherwise by more than a margin.
#pragma once

#include <vector>

#include "pipeline/depth/segment_planes.h"
#include "pipeline/depth/superpixels.h"

namespace px::depth {

struct WeakRegionOptions {
  float same_colour_lab = 6.0f;  // touching segments closer than this in mean Lab join one region
  int min_segments = 3;          // smaller regions are left as they are
  double cost_margin = 0.02;     // a member keeps its plane when the region's is worse by more
  int max_candidates = 48;       // the planes a region weighs: the most widely held first
};

struct WeakRegionStats {
  int regions = 0;           // regions of min_segments or more
  int changed_segments = 0;  // segments whose plane changed
};

// `cost(segment, plane)` is the mean matching cost of a plane over a segment (lower is better).
// Changes only segments whose source is PlaneSource::kPropagated. Deterministic.
WeakRegionStats UnifyWeakRegions(const Superpixels& segments,
                                 const PlaneCost& cost,
                                 const WeakRegionOptions& options,
                                 std::vector<SegmentPlane>* planes);

}  // namespace px::depth
