// Stage 1: cut one multi-lens sensor frame into its tiles, each turned upright.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "pipeline/core/lattice_layout.h"
#include "pipeline/core/status.h"

namespace px {

// Crops every tile of `layout` out of `sensor_bgr` (CV_8UC3, sensor_width x sensor_height),
// resampling tiles with a rotation_deg (bilinear), and undoes its TileOrientation, so each result shows the scene
// upright as its lens saw it. The result is in view order (row-major, index = view id) and owns its pixels (no aliasing
// of the sensor frame). Fails with INVALID_ARGUMENT on a bad layout, an empty or non-BGR frame, or a frame whose size
// differs from the layout's sensor size.
StatusOr<std::vector<cv::Mat>> SplitLattice(const cv::Mat& sensor_bgr, const LatticeLayout& layout);

// The pixels of one tile as stored on the sensor (before its orientation is undone): a view of
// `sensor`'s rect for an axis-aligned tile, else the rotated tile resampled (bilinear) into a
// fresh rect-sized image. The sensor's type is kept; the layout is not checked here.
cv::Mat CutStoredTile(const cv::Mat& sensor, const Tile& tile);

// Turns one stored tile upright: the inverse of how `orientation` says it lies on the sensor.
// kRotated180 rotates by 180 degrees, kMirroredX flips left-right, kMirroredY flips top-bottom.
cv::Mat MakeTileUpright(const cv::Mat& stored_tile, TileOrientation orientation);

}  // namespace px
