// Where each lens's sub-image (tile) lies on a multi-lens sensor frame.
#pragma once

#include <array>
#include <opencv2/core.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "pipeline/core/status.h"

namespace px {

// How a tile's pixels must be turned to show the scene upright. A single lens inverts its
// image, so tiles behind individual lenses are often rotated by 180 degrees on the sensor.
enum class TileOrientation { kUpright, kRotated180, kMirroredX, kMirroredY };

std::string_view TileOrientationName(TileOrientation orientation);  // "upright", "rotated180", ...
StatusOr<TileOrientation> ParseTileOrientation(std::string_view name);

// What a source knows of its lattice without a calibration: how many tiles (0 = unknown, found
// blind) and how each tile's picture lies in the frame (a photo of a film scan or a multi-lens
// frame, turned upright to be looked at, has upright tiles; a raw sensor's are turned 180 degrees
// by their lenses).
struct LatticeHint {
  int rows = 0;
  int cols = 0;
  TileOrientation orientation = TileOrientation::kUpright;
};

struct Tile {
  static constexpr double kMaxRotationDeg = 45.0;

  int row = 0;    // lattice row, 0 = top as seen from behind the camera
  int col = 0;    // lattice column, 0 = left
  cv::Rect rect;  // sub-image on the sensor, in sensor pixels (before rotation_deg)
  TileOrientation orientation = TileOrientation::kUpright;
  // A lens or mask mounted slightly askew turns its sub-image: the tile's pixels lie on `rect`
  // turned by this angle about the rect's centre, degrees, positive = clockwise as the sensor
  // image is displayed (x right, y down); [-45, 45], usually within a degree or two. 0 = axis-aligned.
  double rotation_deg = 0.0;
};

// The centre of a tile's rect in sensor pixels (pixel centres at integers): the point it turns about.
cv::Point2d TileCentre(const Tile& tile);
// Maps a stored tile pixel (u, v) (u in [0, width), pixel centres at integers, before the tile's
// orientation is undone) to sensor coordinates: TileCentre + R(rotation_deg) * ((u, v) - tile centre).
// For rotation 0 it is the plain offset by rect.tl().
cv::Matx23d SensorFromTile(const Tile& tile);
// The four outer corners of the tile's pixel area on the sensor (top-left, top-right,
// bottom-right, bottom-left of the stored tile), turned by rotation_deg.
std::array<cv::Point2d, 4> TileCorners(const Tile& tile);

struct LatticeLayout {
  int rows = 0;
  int cols = 0;
  int sensor_width = 0;  // the full sensor frame the rectangles refer to
  int sensor_height = 0;
  std::vector<Tile> tiles;  // row-major: tiles[row * cols + col]; view id = index

  // A regular grid: tiles of tile_width x tile_height separated by gap_px of dark border,
  // with a gap_px margin around the frame.
  static LatticeLayout Regular(int rows,
                               int cols,
                               int tile_width,
                               int tile_height,
                               int gap_px,
                               TileOrientation orientation = TileOrientation::kUpright);

  int NumViews() const { return static_cast<int>(tiles.size()); }
  bool HasRotatedTiles() const;
  // rows*cols tiles in row-major order, positive sizes, each inside the sensor, none overlapping,
  // rotations finite and within +-Tile::kMaxRotationDeg.
  Status Validate() const;
};

}  // namespace px
