// The establishing dolly (paper section 3): for a scene with no subject of interest, the camera
// dollies sideways across the scene to show its parallax, with the capture's focal length.
#pragma once

#include <vector>

#include "pipeline/core/view.h"
#include "pipeline/direct/camera_path.h"

namespace px {

// A linear sideways dolly across the views' camera centres: from one side of their bounding box
// to the other along its longer axis, at the box centre's height and depth (z = 0 for a lattice
// rig, whose frame is centred on the lenses). Orientation: parallel to the mean view axis, or
// with options.converge aimed at the median scene depth on that axis. Intrinsics (size,
// focal length, principal point) are those of the view nearest the box centre.
// Fails when views and depths do not match or the centres do not span a line.
StatusOr<CameraPath> PlanEstablishingDolly(const std::vector<View>& views, const std::vector<DepthMap>& depths,
                                           const DirectOptions& options);

// Median of the known (positive, finite) depths over all maps, sampling every `stride`-th pixel
// in each direction; 0 when no depth is known.
double MedianSceneDepth(const std::vector<DepthMap>& depths, int stride = 4);

}  // namespace px
