// Options of the first plane sweep (plane_sweep.h), kept as the evaluation's reference method.
// Every field has a default, a unit and a range; Validate() names the first bad field and its value.
#pragma once

#include "pipeline/core/status.h"

namespace px {

struct PlaneSweepOptions {
  // Scene depth range swept, in metres (z in the reference camera). 0 = not set: the caller
  // fills it from the rig's nominal range (WithDefaultDepthRange). When set: 0 < min < max.
  double min_depth_m = 0;
  double max_depth_m = 0;
  // Fronto-parallel planes sampled uniformly in inverse depth between the two. [2, 1024]. More
  // planes cost linearly more time; sub-plane accuracy comes from parabolic refinement, so a
  // step of about half a pixel of disparity between the nearest views is enough.
  int num_planes = 64;
  // Matching window radius in pixels at the working scale: the window is (2r+1)^2. [1, 15].
  int window_radius_px = 3;
  // Neighbour views each reference view is matched against, nearest camera centres first.
  // [1, 16]; fewer are used when the shot has fewer other views.
  int num_neighbors = 4;
  // Depth is computed at this fraction of the view resolution, then upsampled edge-aware to full
  // resolution. (0, 1]; 0.5 is about 4x faster than 1 with little loss on smooth surfaces.
  double working_scale = 0.5;
  // Guided-filter aggregation of every cost slice, guided by the reference image (cost-volume
  // filtering): radius in pixels at the working scale, [0, 15], 0 = off. It fills weakly
  // textured areas from textured ones of the same surface and sharpens depth edges.
  int cost_filter_radius_px = 4;
  // Guided-filter edge threshold: grey variance (image in [0, 1]) above which a window keeps its
  // own costs. [1e-6, 1].
  double cost_filter_eps = 1e-4;
  // Grey-level standard deviation (images scaled to [0, 1]) under which a window counts as
  // textureless: its matching cost is neutral, so its confidence is 0. [0, 0.5].
  double min_texture_stddev = 0.004;
  // Connected regions of at most this many pixels (at the working scale) whose depth differs
  // from their surroundings by more than two planes are speckles: they keep their depth but get
  // low confidence. [0, 1e6]; 0 disables the check.
  int speckle_max_size_px = 64;
  // Confidence in [0, 1] under which a pixel's depth is replaced (blended) by an edge-aware fill
  // from confident neighbours guided by the image. 0 disables the fill.
  double fill_confidence = 0.15;
  // Worker threads: 0 = OpenCV's default (all cores). [0, 256].
  int num_threads = 0;

  Status Validate() const;
  // A copy whose unset (0) depth bounds are taken from the rig's nominal range.
  PlaneSweepOptions WithDefaultDepthRange(double nominal_min_m, double nominal_max_m) const;
  bool HasDepthRange() const { return min_depth_m > 0 && max_depth_m > 0; }
};

}  // namespace px
