// Factory rig calibration: from several captures of a checkerboard seen through every lens,
// each tile's intrinsics and distortion (OpenCV calibrateCamera) and every tile's pose in the rig
// frame (stereo calibration of each tile against the centre tile through the captures both saw,
// intrinsics fixed). The rig frame is then centred on the lenses and turned to their mean
// orientation (x right, y down, z forward, as rig_calibration.h says).
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "pipeline/calib/board_detector.h"
#include "pipeline/core/lattice_layout.h"
#include "pipeline/core/rig_calibration.h"
#include "pipeline/core/status.h"

namespace px {

struct RigCalibratorOptions {
  CalibrationBoard board;
  std::string rig_name = "factory";
  // A tile needs the board in at least this many captures, [3, 100].
  int min_boards_per_tile = 3;
  // Fit k3 (OpenCV's sixth-order radial term) too; off by default: with a few boards it
  // trades against k1/k2 and extrapolates badly into the corners.
  bool fit_k3 = false;
  // Fit tangential distortion (p1, p2). Off by default: lenses in a moulded lattice are centred
  // well, and with the board in the middle of the view p1/p2 trade against the principal point.
  bool fit_tangential = false;
  // A tile whose board reprojection RMS exceeds this is reported in the warnings, pixels, (0, 10].
  double warn_rms_px = 0.5;

  Status Validate() const;
};

struct TileCalibrationFigures {
  int view = 0;
  int boards_found = 0;           // captures whose board was found in this tile
  double rms_px = 0;              // board reprojection RMS of its intrinsic calibration
  int shared_with_reference = 0;  // captures used for its pose (board also in the reference tile)
  double pose_rms_px = 0;         // stereo reprojection RMS of its pose (0 for the reference)
};

struct RigCalibrationReport {
  int captures = 0;
  int reference_view = 0;  // the tile poses were chained through
  std::vector<TileCalibrationFigures> tiles;
  std::vector<std::string> warnings;
  double ms = 0;

  std::string Summary() const;  // one line
};

struct RigCalibrationResult {
  RigCalibration rig;
  RigCalibrationReport report;
};

// `tiles_by_capture[k][v]` is capture k's upright tile v (SplitLattice of a frame with `layout`).
// INVALID_ARGUMENT for bad options, fewer than min_boards_per_tile captures or a capture with the
// wrong number of tiles; NOT_FOUND naming the tile when the board is in too few of its captures or
// never in the same capture as the reference tile.
StatusOr<RigCalibrationResult> CalibrateRig(const std::vector<std::vector<cv::Mat>>& tiles_by_capture,
                                            const LatticeLayout& layout,
                                            const RigCalibratorOptions& options);

}  // namespace px
