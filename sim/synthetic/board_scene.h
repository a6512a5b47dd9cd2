// Calibration board captures for factory rig calibration: a printed checkerboard (on a white
// card) at chosen poses in front of the simulated lattice camera, rendered through every lens
// onto the sensor. The board poses and the camera spec are the ground truth.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "pipeline/core/rigid3.h"
#include "pipeline/core/status.h"
#include "sim/synthetic/scene.h"
#include "sim/synthetic/sim_camera.h"

namespace px::sim {

struct SimBoard {
  // Inner corners (where four squares meet) across and down; both odd so that the board has an
  // even number of squares each way and its centre is a corner. [3, 25]
  int inner_cols = 7;
  int inner_rows = 5;
  double square_m = 0.02;  // side of one square, (0, 1]
  double border_m = 0.02;  // white card around the squares, [0, 1]

  Status Validate() const;
  // Corner (i, j) (i across, j down, row-major) in the board frame: x right, y down, z = 0 on the
  // board, origin at the top-left inner corner.
  std::vector<cv::Point3f> Corners() const;
};

// The board at rig_from_board (board frame as in SimBoard::Corners) in front of a grey noise
// backdrop 2 m away.
Scene MakeBoardScene(const SimBoard& board, const Rigid3& rig_from_board);

// `count` poses that fill much of every lens's view of `spec`: the board spanning 55 to 75 % of
// the tile width, its centre moved sideways by up to 5 % of the view, tilted by up to 35 degrees
// about x and y and turned by up to 15 degrees in its plane. Deterministic in `seed`.
std::vector<Rigid3> BoardPoses(const SimBoard& board, const SimCameraSpec& spec, int count, uint64_t seed);

struct BoardCapture {
  cv::Mat sensor_bgr;     // the whole sensor frame, CV_8UC3
  Rigid3 rig_from_board;  // truth
};

// Renders one sensor frame per pose through `spec` (vignetting, noise, distortion as it says).
StatusOr<std::vector<BoardCapture>> RenderBoardCaptures(const SimCameraSpec& spec,
                                                        const SimBoard& board,
                                                        const std::vector<Rigid3>& rig_from_board,
                                                        uint64_t seed);

}  // namespace px::sim
