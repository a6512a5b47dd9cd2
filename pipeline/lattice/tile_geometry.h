// A tile's rectangle and rotation from its four edge lines (tile_edge_fit.h).
#pragma once

#include <array>
#include <opencv2/core.hpp>

#include "pipeline/lattice/tile_edge_fit.h"

namespace px::lattice {

enum TileSide { kLeft = 0, kRight = 1, kTop = 2, kBottom = 3 };

struct TileEdges {
  // left/right: x = a + b * y; top/bottom: y = a + b * x (sensor pixels, pixel centres at integers).
  std::array<EdgeLine, 4> lines;
  // How much each line's direction is trusted for the tile's rotation (0: position only, e.g. the
  // frame's border or a fallback).
  std::array<double, 4> angle_weight = {0, 0, 0, 0};
};

struct TileGeometry {
  cv::Point2d centre;  // pixel centres at integers
  double width = 0;    // between the left and right lines, pixels
  double height = 0;
  double rotation_deg = 0;  // clockwise as displayed (y down), as Tile::rotation_deg

  // The rounded tile rectangle whose TileCentre is nearest `centre`.
  cv::Rect Rect() const;
};

TileGeometry GeometryFromEdges(const TileEdges& edges);

}  // namespace px::lattice
