#include "pipeline/lattice/tile_geometry.h"

#include <cmath>

namespace px::lattice {
namespace {

// Where a vertical line x = av + bv y meets a horizontal one y = ah + bh x.
cv::Point2d Intersect(const EdgeLine& vertical, const EdgeLine& horizontal) {
  const double x = (vertical.a + vertical.b * horizontal.a) / (1.0 - vertical.b * horizontal.b);
  return {x, horizontal.a + horizontal.b * x};
}

}  // namespace

cv::Rect TileGeometry::Rect() const {
  const int w = static_cast<int>(std::lround(width));
  const int h = static_cast<int>(std::lround(height));
  return {static_cast<int>(std::lround(centre.x - (w - 1) * 0.5)),
          static_cast<int>(std::lround(centre.y - (h - 1) * 0.5)),
          w,
          h};
}

TileGeometry GeometryFromEdges(const TileEdges& edges) {
  TileGeometry g;
  // A tile turned clockwise by theta: its vertical edges run along (-sin, cos), so dx/dy = -tan;
  // its horizontal edges along (cos, sin), so dy/dx = tan.
  double sum = 0, weight = 0;
  for (int side = 0; side < 4; ++side) {
    const double w = edges.angle_weight[side];
    if (w <= 0) continue;
    const double angle = side <= kRight ? std::atan(-edges.lines[side].b) : std::atan(edges.lines[side].b);
    sum += w * angle;
    weight += w;
  }
  const double theta = weight > 0 ? sum / weight : 0.0;
  g.rotation_deg = theta * 180.0 / CV_PI;
  const cv::Point2d tl = Intersect(edges.lines[kLeft], edges.lines[kTop]);
  const cv::Point2d tr = Intersect(edges.lines[kRight], edges.lines[kTop]);
  const cv::Point2d bl = Intersect(edges.lines[kLeft], edges.lines[kBottom]);
  const cv::Point2d br = Intersect(edges.lines[kRight], edges.lines[kBottom]);
  g.centre = 0.25 * (tl + tr + bl + br);
  // Distances between opposite lines, measured across them at the centre.
  const double c = std::cos(theta);
  g.width = (edges.lines[kRight].a + edges.lines[kRight].b * g.centre.y - edges.lines[kLeft].a -
             edges.lines[kLeft].b * g.centre.y) *
            c;
  g.height = (edges.lines[kBottom].a + edges.lines[kBottom].b * g.centre.x - edges.lines[kTop].a -
              edges.lines[kTop].b * g.centre.x) *
             c;
  return g;
}

}  // namespace px::lattice
