// Options for rendering novel views from views with depth (paper section 6).
#pragma once

#include "pipeline/core/status.h"

namespace px {

struct RenderOptions {
  // Source views blended per frame: the nearest ones to the virtual camera, [1, 64]. The paper
  // blends the three views of the view-mesh triangle the ray crosses.
  int num_source_views = 3;
  // Soft z-buffer band (paper eq. 1), relative to the nearest candidate depth, (0, 1]: a source
  // whose surface lies farther than nearest * (1 + band) is hidden there; within the band the
  // weight falls from 1 (first quarter) to 0 by a raised cosine.
  double soft_z_band = 0.05;
  // A source pixel's footprint in the target may grow to this many times its expected size
  // before it counts as spanning a depth discontinuity and is dropped, [1, 10].
  double max_splat_stretch = 2.0;
  // Holes are filled from the covered pixels within this radius, weighted towards the farthest
  // (disocclusions reveal background; the paper fills holes under 6 px this way), and larger
  // holes ring by ring inwards with the same radius. Pixels, [1, 16].
  int hole_fill_radius_px = 3;

  Status Validate() const;
};

}  // namespace px
