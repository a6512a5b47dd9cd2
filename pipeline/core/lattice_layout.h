// Where each lens's sub-image (tile) lies on a multi-lens sensor frame.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include <opencv2/core.hpp>

#include "pipeline/core/status.h"

namespace px {

// How a tile's pixels must be turned to show the scene upright. A single lens inverts its
// image, so tiles behind individual lenses are often rotated by 180 degrees on the sensor.
enum class TileOrientation { kUpright, kRotated180, kMirroredX, kMirroredY };

std::string_view TileOrientationName(TileOrientation orientation);  // "upright", "rotated180", ...
StatusOr<TileOrientation> ParseTileOrientation(std::string_view name);

struct Tile {
  int row = 0;            // lattice row, 0 = top as seen from behind the camera
  int col = 0;            // lattice column, 0 = left
  cv::Rect rect;          // sub-image on the sensor, in sensor pixels
  TileOrientation orientation = TileOrientation::kUpright;
};

struct LatticeLayout {
  int rows = 0;
  int cols = 0;
  int sensor_width = 0;   // the full sensor frame the rectangles refer to
  int sensor_height = 0;
  std::vector<Tile> tiles;  // row-major: tiles[row * cols + col]; view id = index

  // A regular grid: tiles of tile_width x tile_height separated by gap_px of dark border,
  // with a gap_px margin around the frame.
  static LatticeLayout Regular(int rows, int cols, int tile_width, int tile_height, int gap_px,
                               TileOrientation orientation = TileOrientation::kUpright);

  int NumViews() const { return static_cast<int>(tiles.size()); }
  // rows*cols tiles in row-major order, positive sizes, each inside the sensor, none overlapping.
  Status Validate() const;
};

}  // namespace px
