// Seams between segments of one surface, closed before rendering (ALGORITHM.md section 1).
// Neighbouring segments on one surface have slightly different fitted planes, so in a novel view
// their projections separate along the seam, by a pixel or more where the view is magnified (a
// close-up). Each masked bilinear sample then has alpha < 1 there, and a farther segment whose
// homography maps the pixel to its own texels elsewhere (the wall behind a face) fills the rest: a
// thin light crack, in every view alike, so the soft z-buffer cannot hide it.
//
// The fix: every texel on a seam between two segments of one surface (no depth edge: their planes
// agree within `max_step` at the texel, but by no less than `min_step`: planes that agree closer
// cannot part visibly in the views the product plans) also carries the neighbouring segment, in its free layer 1
// with weight `weight` and the texel's own colour: a *skirt* one texel wide, so that each segment
// reaches one texel under its neighbour. Compositing saturates (f = min(alpha, 1 - A)), so where
// the projections agree little changes (the first segment drawn fills more of the pixel, see
// SeamSkirtOptions::weight for the cost); where they separate by up to a source texel the skirt
// covers the gap with the surface's own colour. Depth edges have a two-layer band (layer 1 taken)
// and planes that disagree: they get no skirt, so silhouettes do not grow. The weights of a skirted
// texel sum to more than 1: the result is the renderer's own input, not a LayeredDepthView for
// anyone else (ValidateLayeredDepthView refuses it).
#pragma once

#include "pipeline/core/layered_depth.h"
#include "pipeline/render/seam_skirt_options.h"

namespace px::render {

struct SeamSkirtReport {
  int skirt_texels = 0;  // texels given a neighbour's segment in layer 1
};

// `view` with skirts on its same-surface seams: layer 1 and the segments' bboxes (grown to their
// skirts) are copies, the rest shared. options.max_step = 0: the view as it is.
LayeredDepthView WithSeamSkirts(const LayeredDepthView& view,
                                const SeamSkirtOptions& options,
                                SeamSkirtReport* report = nullptr);

}  // namespace px::render
