// Options of the consistent blend (contradictions.h, ALGORITHM.md sections 1 and 5): where the
// views a pixel blends disagree beyond what noise and lighting explain (a subject that moved
// between shots, a sliver of wrong depth, a silhouette one view draws too wide), the pixel is
// drawn from the views that the more heavily weighted ones do not contradict. Ours, not the paper's.
#pragma once

#include "pipeline/core/status.h"

namespace px {

struct ConsistentBlendOptions {
  bool enabled = true;
  // A view contradicts a surface when, along its own ray through the surface's point, everything
  // it sees lies farther than the point by more than this many pixels of disparity between the
  // two views. (0, 100].
  double free_space_px = 1.5;
  // ... and what it sees there differs from the surface's colour by more than this many levels
  // (largest channel, 0..255; under it, the views agree on what is there whatever their depth
  // says). [1, 255].
  int colour_levels = 24;
  // Views whose surfaces lie close together in depth (the soft z blends them) but whose colours
  // differ by more than colour_agree_levels (largest channel) show two images of one place (their
  // depth is off, or the subject moved along itself): the lighter view yields as if contradicted,
  // in full from colour_apart_levels (colour_apart_levels <= colour_agree_levels: off).
  // [0, 255] each.
  int colour_agree_levels = 16;
  int colour_apart_levels = 32;
  // Where the consensus outvotes several views in one region (each at its own copy of a thin
  // structure the views place a few pixels apart), draw that region from its most heavily
  // weighted view alone: the structure shows once and whole, where the vote cuts it into dashes,
  // but at that view's place, which costs leave-one-out fidelity and flickers as the heaviest view
  // changes (pipeline/render/README.md, known limitations). Off by default.
  bool one_view_regions = false;
  // Views checked against each view: of those that can share a pixel with it, the nearest by
  // camera centre. [1, 16].
  int max_neighbours = 8;
  // How fast the more heavily weighted view takes over a contested pixel: a contradicting view j
  // suppresses slot k by v_j^e / (v_j^e + v_k^e) of its share (viewing weights v, flattened by
  // RenderOptions::viewing_weight_exponent). [1, 64].
  double dominance_exponent = 8;

  Status Validate() const;
};

}  // namespace px
