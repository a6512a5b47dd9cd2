// Planes of touching segments of one surface made to agree along their shared border, once per
// scene before rendering. Each segment's plane is fitted on its own, so two neighbours
// on one surface disagree a little at their seam; a magnified view parts them there (cracks, which
// the seam skirts cover) and, along a silhouette, puts each segment's piece of the edge somewhere
// slightly different (a staircase, which no skirt can cover). Here all of a view's planes are
// refitted together, by least squares over their inverse depth: each stays close to its own fit
// over its own pixels, and at every seam pixel between two segments of one surface the two planes
// are pulled to the same value. Depth edges (a two-layer band, or planes far apart) are left alone.
#pragma once

#include "pipeline/core/layered_depth.h"

namespace px {

struct SeamPlaneOptions {
  // Weight of agreement at one seam pixel pair against one pixel's own fit; 0 = off. [0, 1e4].
  // Off by default: 16 gains 0.14 dB and a straighter silhouette on the simulated close-ups and
  // 0.13 dB on HCI but loses 0.04 dB on LLFF fern (under LLFF's 24.13) and 0.02 dB
  // on the standard simulated viewpoints (pipeline/render/README.md); the depth stage, which knows
  // its own fit's uncertainty, is the better place for it.
  double seam_weight = 0;
  // Touching segments are one surface when their planes' inverse depths at the seam differ by
  // less than this fraction (relative); as SeamSkirtOptions::max_step. (0, 1).
  double max_step = 0.05;
};

}  // namespace px

namespace px::render {

struct SeamPlaneReport {
  int seam_pairs = 0;      // pixel pairs across same-surface seams
  int planes_changed = 0;  // segments given the joint fit's plane
};

// `view` with its planes refitted jointly (segments and depth_m copied, where a plane changed
// depth_m follows it; the layers shared). A plane that the fit would make non-positive over its
// bbox keeps its own. Off, or nothing to join: `view` as it is.
LayeredDepthView WithSeamPlanes(const LayeredDepthView& view,
                                const SeamPlaneOptions& options,
                                SeamPlaneReport* report = nullptr);

}  // namespace px::render
