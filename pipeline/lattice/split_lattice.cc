#include "pipeline/lattice/split_lattice.h"

#include <opencv2/imgproc.hpp>
#include <sstream>

namespace px {

cv::Mat MakeTileUpright(const cv::Mat& stored_tile, TileOrientation orientation) {
  cv::Mat upright;
  switch (orientation) {
    case TileOrientation::kUpright:
      upright = stored_tile.clone();
      break;
    case TileOrientation::kRotated180:
      cv::rotate(stored_tile, upright, cv::ROTATE_180);
      break;
    case TileOrientation::kMirroredX:
      cv::flip(stored_tile, upright, 1);
      break;
    case TileOrientation::kMirroredY:
      cv::flip(stored_tile, upright, 0);
      break;
  }
  return upright;
}

StatusOr<std::vector<cv::Mat>> SplitLattice(const cv::Mat& sensor_bgr, const LatticeLayout& layout) {
  PX_RETURN_IF_ERROR(layout.Validate());
  if (sensor_bgr.empty()) return InvalidArgumentError("sensor frame is empty");
  if (sensor_bgr.type() != CV_8UC3) {
    std::ostringstream error;
    error << "sensor frame has " << sensor_bgr.channels() << " channels of depth " << sensor_bgr.depth()
          << ", want 8-bit BGR (CV_8UC3)";
    return InvalidArgumentError(error.str());
  }
  if (sensor_bgr.cols != layout.sensor_width || sensor_bgr.rows != layout.sensor_height) {
    std::ostringstream error;
    error << "sensor frame is " << sensor_bgr.cols << "x" << sensor_bgr.rows << ", lattice expects "
          << layout.sensor_width << "x" << layout.sensor_height;
    return InvalidArgumentError(error.str());
  }
  std::vector<cv::Mat> tiles;
  tiles.reserve(layout.tiles.size());
  for (const Tile& tile : layout.tiles) {
    tiles.push_back(MakeTileUpright(CutStoredTile(sensor_bgr, tile), tile.orientation));
  }
  return tiles;
}

cv::Mat CutStoredTile(const cv::Mat& sensor, const Tile& tile) {
  if (tile.rotation_deg == 0.0) return sensor(tile.rect);
  cv::Mat stored;
  // dst (u, v) samples the sensor at SensorFromTile * (u, v, 1); pixels past the frame repeat its edge.
  cv::warpAffine(sensor,
                 stored,
                 cv::Mat(SensorFromTile(tile)),
                 tile.rect.size(),
                 cv::INTER_LINEAR | cv::WARP_INVERSE_MAP,
                 cv::BORDER_REPLICATE);
  return stored;
}

}  // namespace px
