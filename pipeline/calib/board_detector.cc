#include "pipeline/calib/board_detector.h"

#include <algorithm>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

namespace px {

Status CalibrationBoard::Validate() const {
  std::ostringstream error;
  if (inner_cols < 3 || inner_cols > 50)
    error << "inner_cols " << inner_cols << " is outside [3, 50]";
  else if (inner_rows < 3 || inner_rows > 50)
    error << "inner_rows " << inner_rows << " is outside [3, 50]";
  else if (!(square_m > 0 && square_m <= 1))
    error << "square_m " << square_m << " is outside (0, 1]";
  if (error.str().empty()) return OkStatus();
  return InvalidArgumentError("calibration board: " + error.str());
}

std::vector<cv::Point3f> CalibrationBoard::Corners() const {
  std::vector<cv::Point3f> corners;
  for (int j = 0; j < inner_rows; ++j) {
    for (int i = 0; i < inner_cols; ++i) {
      corners.emplace_back(static_cast<float>(i * square_m), static_cast<float>(j * square_m), 0.0f);
    }
  }
  return corners;
}

StatusOr<std::vector<cv::Point2f>> DetectBoardCorners(const cv::Mat& tile_bgr, const CalibrationBoard& board) {
  PX_RETURN_IF_ERROR(board.Validate());
  if (tile_bgr.empty() || (tile_bgr.type() != CV_8UC3 && tile_bgr.type() != CV_8UC1)) {
    return InvalidArgumentError("board detection: the tile is empty or not 8-bit BGR/grey");
  }
  cv::Mat grey;
  if (tile_bgr.channels() == 3) {
    cv::cvtColor(tile_bgr, grey, cv::COLOR_BGR2GRAY);
  } else {
    grey = tile_bgr;
  }
  std::vector<cv::Point2f> corners;
  const cv::Size pattern(board.inner_cols, board.inner_rows);
  if (!cv::findChessboardCornersSB(grey, pattern, corners, cv::CALIB_CB_ACCURACY)) {
    return NotFoundError("no " + std::to_string(board.inner_cols) + "x" + std::to_string(board.inner_rows) +
                         " checkerboard found in the " + std::to_string(grey.cols) + "x" + std::to_string(grey.rows) +
                         " tile");
  }
  // Rows must run left to right and down the image: fix the two symmetric orderings.
  const cv::Point2f first = corners.front(), last = corners.back();
  if (first.x + first.y > last.x + last.y) std::reverse(corners.begin(), corners.end());
  const cv::Point2f along_row = corners[board.inner_cols - 1] - corners[0];
  const cv::Point2f down_cols = corners[(board.inner_rows - 1) * board.inner_cols] - corners[0];
  if (along_row.x * down_cols.y - along_row.y * down_cols.x < 0) {
    // Transposed or mirrored ordering: not a board seen from the front in this convention.
    return NotFoundError("the checkerboard's corners come out mirrored in the tile (is it seen from behind?)");
  }
  return corners;
}

}  // namespace px
