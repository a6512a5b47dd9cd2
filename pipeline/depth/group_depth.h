// Coplanar groups' planes moved along the viewing rays to where the full-resolution views agree.
//
// Matching runs at half resolution on the product's lattice, in plane steps of one pixel there,
// and the sub-plane position between steps comes from a parabola through the costs: that leaves
// a photograph or a wall 0.2 to 0.5 % too near in every view, invisible at the lenses'
// viewpoints and magnified into doubled edges at the close-up end of a dolly in
// (pipeline/depth/README.md). A coplanar group (coplanar_groups.h) has thousands of pixels, so its
// depth can be read far more finely: the group's plane is scaled along the rays in small steps,
// each scored by the exact multi-view ZNCC (segment_match_cost.h) over the group's interior at
// view resolution. Only the interior: pixels near the group's border see other surfaces in some
// neighbours and pull the plane off its true depth.
#pragma once

#include <vector>

#include "pipeline/depth/two_layer.h"
#include "pipeline/depth/working_view.h"

namespace px::depth {

struct GroupDepthOptions {
  // Inverse depth (1/m) of one pixel of disparity against the nearest neighbour, at the
  // reference's resolution: the unit of the search. > 0.
  double pixel_inverse_depth = 0;
  // A pixel is interior when the pixels this far away in the 8 directions are in its group.
  int interior_px = 12;
  int sample_step_px = 2;             // every this many pixels in x and y, [1, 16]
  double search_px = 0.1;             // the plane moves at most this much disparity, (0, 4]
  double step_px = 0.02;              // in steps of this, refined by a parabola, (0, search_px]
  int min_samples = 200;              // groups with fewer interior samples stay, >= 16
  int max_samples = 2000;             // larger groups are read at evenly spread samples, >= min_samples
  double min_texture_stddev = 0.004;  // grey [0, 1]: groups whose samples vary less stay
};

struct GroupDepthStats {
  int groups = 0;                // groups with enough interior to search
  int moved = 0;                 // of them, groups whose plane moved
  double mean_abs_shift_px = 0;  // over the searched groups, in disparity
};

// `group_of` gives each segment's group (-1: none), indexed like image->planes; a group's
// members share one plane (MergeCoplanarSegments). `reference` and `neighbours` (at most 16) are
// working views at the reference's full resolution (MakeWorkingView with scale 1), `image` at
// the same resolution. Scales the members' planes by the best factor.
GroupDepthStats RefineGroupDepths(const WorkingView& reference,
                                  const std::vector<const WorkingView*>& neighbours,
                                  const std::vector<int>& group_of,
                                  const GroupDepthOptions& options,
                                  SegmentImage* image);

}  // namespace px::depth
