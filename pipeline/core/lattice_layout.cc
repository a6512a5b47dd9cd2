#include "pipeline/core/lattice_layout.h"

#include <cmath>
#include <sstream>

namespace px {

std::string_view TileOrientationName(TileOrientation orientation) {
  switch (orientation) {
    case TileOrientation::kUpright:
      return "upright";
    case TileOrientation::kRotated180:
      return "rotated180";
    case TileOrientation::kMirroredX:
      return "mirrored_x";
    case TileOrientation::kMirroredY:
      return "mirrored_y";
  }
  return "upright";
}

StatusOr<TileOrientation> ParseTileOrientation(std::string_view name) {
  for (auto o : {TileOrientation::kUpright,
                 TileOrientation::kRotated180,
                 TileOrientation::kMirroredX,
                 TileOrientation::kMirroredY}) {
    if (TileOrientationName(o) == name) return o;
  }
  return InvalidArgumentError("tile orientation '" + std::string(name) +
                              "' is not one of upright, rotated180, mirrored_x, mirrored_y");
}

cv::Point2d TileCentre(const Tile& tile) {
  return {tile.rect.x + (tile.rect.width - 1) * 0.5, tile.rect.y + (tile.rect.height - 1) * 0.5};
}

cv::Matx23d SensorFromTile(const Tile& tile) {
  const double angle = tile.rotation_deg * CV_PI / 180.0;
  const double c = std::cos(angle), s = std::sin(angle);
  const cv::Point2d centre = TileCentre(tile);
  const double u0 = (tile.rect.width - 1) * 0.5, v0 = (tile.rect.height - 1) * 0.5;
  // sensor = centre + R * ((u, v) - (u0, v0))
  return {c, -s, centre.x - (c * u0 - s * v0), s, c, centre.y - (s * u0 + c * v0)};
}

std::array<cv::Point2d, 4> TileCorners(const Tile& tile) {
  const cv::Matx23d m = SensorFromTile(tile);
  const double w = tile.rect.width, h = tile.rect.height;
  std::array<cv::Point2d, 4> corners;
  const cv::Point2d uv[4] = {{-0.5, -0.5}, {w - 0.5, -0.5}, {w - 0.5, h - 0.5}, {-0.5, h - 0.5}};
  for (int i = 0; i < 4; ++i) {
    corners[i] = {m(0, 0) * uv[i].x + m(0, 1) * uv[i].y + m(0, 2), m(1, 0) * uv[i].x + m(1, 1) * uv[i].y + m(1, 2)};
  }
  return corners;
}

bool LatticeLayout::HasRotatedTiles() const {
  for (const Tile& tile : tiles) {
    if (tile.rotation_deg != 0.0) return true;
  }
  return false;
}

LatticeLayout LatticeLayout::Regular(
    int rows, int cols, int tile_width, int tile_height, int gap_px, TileOrientation orientation) {
  LatticeLayout layout;
  layout.rows = rows;
  layout.cols = cols;
  layout.sensor_width = cols * tile_width + (cols + 1) * gap_px;
  layout.sensor_height = rows * tile_height + (rows + 1) * gap_px;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      Tile tile;
      tile.row = r;
      tile.col = c;
      tile.rect =
          cv::Rect(gap_px + c * (tile_width + gap_px), gap_px + r * (tile_height + gap_px), tile_width, tile_height);
      tile.orientation = orientation;
      layout.tiles.push_back(tile);
    }
  }
  return layout;
}

Status LatticeLayout::Validate() const {
  std::ostringstream error;
  if (rows <= 0 || cols <= 0) {
    error << "lattice " << rows << "x" << cols << " has no tiles";
  } else if (static_cast<int>(tiles.size()) != rows * cols) {
    error << "lattice " << rows << "x" << cols << " lists " << tiles.size() << " tiles, want " << rows * cols;
  } else if (sensor_width <= 0 || sensor_height <= 0) {
    error << "sensor size " << sensor_width << "x" << sensor_height << " is not positive";
  }
  const cv::Rect sensor(0, 0, sensor_width, sensor_height);
  for (size_t i = 0; error.str().empty() && i < tiles.size(); ++i) {
    const Tile& t = tiles[i];
    if (t.row != static_cast<int>(i) / cols || t.col != static_cast<int>(i) % cols) {
      error << "tile " << i << " is at row " << t.row << " col " << t.col << ", want row-major order";
    } else if (t.rect.width <= 0 || t.rect.height <= 0) {
      error << "tile " << i << " has size " << t.rect.width << "x" << t.rect.height;
    } else if (!std::isfinite(t.rotation_deg) || std::abs(t.rotation_deg) > Tile::kMaxRotationDeg) {
      error << "tile " << i << " rotation " << t.rotation_deg << " deg is outside [-" << Tile::kMaxRotationDeg << ", "
            << Tile::kMaxRotationDeg << "]";
    } else if ((t.rect & sensor) != t.rect) {
      error << "tile " << i << " at (" << t.rect.x << "," << t.rect.y << ") " << t.rect.width << "x" << t.rect.height
            << " leaves the " << sensor_width << "x" << sensor_height << " sensor";
    } else {
      for (size_t j = 0; j < i; ++j) {
        if ((t.rect & tiles[j].rect).area() > 0) {
          error << "tiles " << j << " and " << i << " overlap";
          break;
        }
      }
    }
  }
  if (error.str().empty()) return OkStatus();
  return InvalidArgumentError("lattice layout: " + error.str());
}

}  // namespace px
