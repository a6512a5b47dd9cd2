// Segment-level PatchMatch (after Bleyer et al. 2011, on superpixels): each segment's plane is
// replaced by a better-scoring one taken from an adjacent segment (propagation) or a random
// perturbation of its own, slant included (refinement), scored by the multi-view matching cost
// summed along the plane over the segment's pixels. A segment's own pixel fit is only as good as
// its noisy per-pixel depths; propagation lets one well-matched plane spread over a large surface
// (the HCI floor: dark, nearly textureless and steeply slanted), and the slanted scoring is the
// aggregation a fronto-parallel window cannot give a slanted surface.
#pragma once

#include <cstdint>
#include <vector>

#include "pipeline/depth/segment_planes.h"
#include "pipeline/depth/superpixels.h"

namespace px::depth {

struct PlaneRefinementOptions {
  // Sweeps over all segments (alternating forward and backward order); 0 = off.
  int iterations = 3;
  // Random perturbations tried per segment and sweep, each half the size of the one before.
  int random_trials = 6;
  // Size of the first perturbation: of the plane's inverse depth at the segment's centre (1/m),
  // and of each slope (1/m per pixel). > 0.
  double offset_inverse_m = 0;
  double slope_inverse_m_per_px = 0;
  // Candidates whose inverse depth at the segment's centre differs from the segment's plane
  // before refinement by more than this are not tried (0 = no limit).
  double max_change_inverse_m = 0;
  uint64_t seed = 1;
  // Per segment, whether to refine it (empty = all).
  std::vector<char> active;
};

// Refines every segment with a plane (source other than kNone) of `planes` against `cost` (mean
// matching cost of a plane over a segment, lower is better). A segment keeps its source and confidence; only its plane
// changes, and only to one with a lower cost. Returns how many segments changed. Deterministic for a seed.
int RefineSegmentPlanes(const Superpixels& segments,
                        const PlaneCost& cost,
                        const PlaneRefinementOptions& options,
                        std::vector<SegmentPlane>* planes);

}  // namespace px::depth
