// Stage 3: segment-based multi-view stereo with two-layer boundaries (paper section 5).
//
// For each reference view: a plane sweep against its nearest neighbour views without
// rectification (plane-induced homographies from the calibrated cameras), windowed ZNCC costs,
// the best half of the neighbours per pixel (occlusions), edge-aware guided-filter aggregation
// and semi-global aggregation, winner-take-all with sub-plane refinement and a confidence from
// the cost curve; then a consistency check between the views' depths; then an
// over-segmentation of each view (SLIC) with a robust plane per segment; and at depth
// discontinuities the paper's two-layer representation with soft alpha, so that the renderer
// separates foreground from background without halos. See README.md for the figures.
#pragma once

#include <functional>
#include <vector>

#include "pipeline/core/layered_depth.h"
#include "pipeline/core/status.h"
#include "pipeline/core/view.h"
#include "pipeline/depth/depth_options.h"
#include "pipeline/depth/depth_report.h"

namespace px {

// fraction in [0, 1] of the stage done; return false to cancel (the call returns CANCELLED).
using DepthProgressCallback = std::function<bool(double fraction)>;

struct DepthStageResult {
  // One each per computed view, in the order computed (the views' order, or reference_indices).
  // maps[i] is layered[i].ToDepthMap(): depth of the dominant layer's segment plane, and the
  // stereo confidence.
  std::vector<DepthMap> maps;
  std::vector<LayeredDepthView> layered;
  DepthReport report;
};

// Depth for every view. Views must be undistorted pinhole views (calib's MakeViews) with CV_8UC3
// images of their camera's size, at least two of them at distinct centres; options must have a
// depth range (DepthOptions::WithDefaultDepthRange). Errors name the view or field at fault.
// Degraded input (no texture, saturated or black views, a view of another scene) is not an
// error: it lowers confidence and is explained in the report.
StatusOr<DepthStageResult> ComputeLayeredDepth(const std::vector<View>& views,
                                               const DepthOptions& options,
                                               const DepthProgressCallback& progress = {});

// Depth for views[reference_indices] only; every view serves as a neighbour (e.g. the centre of
// a light field).
StatusOr<DepthStageResult> ComputeLayeredDepthForViews(const std::vector<View>& views,
                                                       const std::vector<int>& reference_indices,
                                                       const DepthOptions& options,
                                                       const DepthProgressCallback& progress = {});

// The plain depth maps of ComputeLayeredDepth, for consumers that want one depth per pixel.
StatusOr<std::vector<DepthMap>> ComputeDepth(const std::vector<View>& views,
                                             const DepthOptions& options,
                                             const DepthProgressCallback& progress = {});

}  // namespace px
