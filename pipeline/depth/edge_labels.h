// Pixels along depth edges re-choose their segment by what the other views see there.
//
// Segment labels come from colour (SLIC at the working scale, upsampled along the colour edges),
// so where a foreground object meets a background of similar colour, the label boundary can sit
// a pixel or two off the true silhouette: background pixels then ride on the foreground's plane
// (a halo that moves with the object in a novel view) or the object's rim on the background's.
// Colour cannot settle it; parallax can. Each pixel within `radius_px` of a depth edge tries the
// planes of the segments around it: carried through each plane into every neighbour view, its
// colour agrees (best half of the neighbours, which leaves out the views where the pixel is
// hidden) only at its true depth. A Potts smoothness term (iterated conditional modes) keeps the
// new boundary from fraying where colours agree under both planes.
//
// Which views hide the pixel follows from the geometry: the reference's own surfaces, as its
// labels put them, splatted into each neighbour say where a candidate's point lies behind
// something nearer there. Such views say nothing about the candidate; the others must all agree.
// The best half alone fails beside an occluder: a background pixel just left of an object is
// hidden in every view to its right, and where those are most of the neighbours (a corner view,
// or a row of them) the best half still holds hidden views, so no candidate looks right and the
// object keeps a fattened rim (the simulated still life's boxes: 2 to 4 px in a side view). The
// surfaces are splatted as the labels stand, so a fattened rim still hides part of the background
// behind itself; splatting the pixels being reconsidered at their farthest candidate instead
// would remove that but let the true rim hide nothing either, and moves HCI's silhouettes out by
// a pixel (eval depth: HCI 3x3's MSE doubles).
#pragma once

#include <vector>

#include "pipeline/core/view.h"
#include "pipeline/depth/two_layer.h"

namespace px::depth {

struct EdgeLabelOptions {
  // Planes that differ by more than this at a pixel (inverse depth, 1/m) make a depth edge. > 0.
  double edge_inverse_depth_m = 0;
  int radius_px = 2;  // pixels this near a depth edge are reconsidered, [1, 8]
  // Colour difference (mean over the channels, 0-255) at which one view's evidence saturates:
  // a view where the pixel is hidden says "wrong" no louder than this. > 0.
  double truncation = 24;
  // Cost of each of the 8 neighbours with another label, in the data term's units. >= 0.
  double smoothness = 2;
  int iterations = 3;  // sweeps of iterated conditional modes, [1, 10]
  // Leave out the views that cannot see a candidate's point (inverse depth there more than
  // edge_inverse_depth_m behind the reference's surface in that view) and average the rest;
  // where fewer than min_visible_views ([1, 16]) see it, the best half of all of them.
  bool visibility = true;
  int min_visible_views = 2;
};

struct EdgeLabelStats {
  int reconsidered = 0;      // pixels near depth edges
  int changed = 0;           // of them, pixels that took another segment
  int dropped_segments = 0;  // segments left with no pixel, removed
};

// `image` holds labels and planes at the reference's resolution (planes in its pixel grid);
// `neighbours` are other views of the scene, calibrated in the same world frame (full
// resolution, at most 16). Changes labels; segments left with no pixel are removed from planes and
// confidence and the others renumbered in order.
EdgeLabelStats RefineDepthEdgeLabels(const View& reference,
                                     const std::vector<const View*>& neighbours,
                                     const EdgeLabelOptions& options,
                                     SegmentImage* image);

}  // namespace px::depth
