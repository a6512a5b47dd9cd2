// Finds a printed checkerboard in one upright tile image (factory calibration, rig_calibrator.h).
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "pipeline/core/status.h"

namespace px {

struct CalibrationBoard {
  int inner_cols = 7;      // inner corners across, [3, 50]
  int inner_rows = 5;      // inner corners down, [3, 50]
  double square_m = 0.02;  // side of one square, metres, (0, 1]

  Status Validate() const;
  // Corner (i, j) at (i, j, 0) * square_m, row-major: the board frame (x right, y down).
  std::vector<cv::Point3f> Corners() const;
};

// The board's inner corners in `tile_bgr` (CV_8UC3 or CV_8UC1), sub-pixel, in board order
// (row-major). A board with an even number of squares both ways looks the same turned by 180
// degrees; the corners are put in the order whose first corner lies top-left in the image (boards
// are shown within +-45 degrees of upright). NOT_FOUND when the board is not (fully) in the tile.
StatusOr<std::vector<cv::Point2f>> DetectBoardCorners(const cv::Mat& tile_bgr, const CalibrationBoard& board);

}  // namespace px
