// Stage 3: a depth map for every view by multi-view plane sweep.
//
// Each reference view is matched against its nearest neighbour views (by camera-centre
// distance). For each fronto-parallel plane z = d in the reference camera (uniform in 1/d), every
// neighbour is warped into the reference view by the plane-induced homography and compared with
// a windowed ZNCC cost; per pixel only the best half of the neighbours' costs is averaged, so a
// point occluded in some neighbours is still matched in the others. The best plane wins, refined
// to sub-plane precision by a parabola in inverse depth, with a confidence from the cost curve.
// Speckles lose confidence, unreliable pixels are filled edge-aware from confident ones, and
// the working-scale result is upsampled edge-aware to full view resolution.
#pragma once

#include <functional>
#include <vector>

#include "pipeline/core/status.h"
#include "pipeline/core/view.h"
#include "pipeline/depth/plane_sweep_options.h"

namespace px {

// fraction in [0, 1] of the stage done; return false to cancel (ComputePlaneSweepDepth returns CANCELLED).
using PlaneSweepProgressCallback = std::function<bool(double fraction)>;

// One DepthMap per view, in the views' order, each at its view's full resolution: depth_m > 0
// everywhere (z in the view's camera, within the swept range), confidence in [0, 1] (0 where no
// neighbour saw the pixel or the window is textureless; such pixels still get the best depth
// available). Views must be undistorted pinhole views (calib's MakeViews) with CV_8UC3 images of
// their camera's size, at least two of them at distinct centres. options must have a depth range
// (see PlaneSweepOptions::WithDefaultDepthRange). Errors name the view or field at fault.
StatusOr<std::vector<DepthMap>> ComputePlaneSweepDepth(const std::vector<View>& views,
                                                       const PlaneSweepOptions& options,
                                                       const PlaneSweepProgressCallback& progress = {});

// The depth map of views[reference_index] alone (the others serve as neighbours).
StatusOr<DepthMap> ComputePlaneSweepDepthForView(const std::vector<View>& views,
                                                 int reference_index,
                                                 const PlaneSweepOptions& options);

}  // namespace px
