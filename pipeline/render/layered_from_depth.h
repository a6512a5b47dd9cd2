// A LayeredDepthView (pipeline/core/layered_depth.h) from a plain per-pixel depth map: square blocks
// become planar segments (least squares in inverse depth), a block that straddles a depth jump is
// split into a near and a far segment, and at the jump the near pixels get a second layer: the far
// segment extended under them, with the pixel's colour and a share of its weight.
//
// It turns exact depth (the simulator's ground truth) into renderer input for the tests and the
// evaluation, and makes the coarse scene the CPU back end's Coverage() draws at reduced size.
#pragma once

#include "pipeline/core/layered_depth.h"
#include "pipeline/core/status.h"
#include "pipeline/core/view.h"

namespace px {

struct LayeredFromDepthOptions {
  // Block side in pixels, [2, 64]: smaller follows curved surfaces more closely and makes more
  // segments to draw.
  int block_px = 8;
  // A block whose inverse depths span more than this fraction of the largest is split at its
  // largest gap (up to four segments per block), (0, 1].
  double jump_ratio = 0.04;
  // Front layer's weight on the near pixels along a jump inside a block; the far segment takes the
  // rest as layer 1. 1 = no second layer. (0, 1].
  double edge_front_weight = 1.0;
};

// `view` gives the camera and colours (undistorted pinhole, CV_8UC3); `depth` its z in metres
// (0, negative or non-finite = unknown, left uncovered) and confidence (CV_32F or empty = 1).
// The result passes ValidateLayeredDepthView.
StatusOr<LayeredDepthView> LayeredDepthFromDepthMap(const View& view,
                                                    const DepthMap& depth,
                                                    const LayeredFromDepthOptions& options = {});

}  // namespace px
