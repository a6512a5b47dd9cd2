#include "sim/synthetic/board_scene.h"

#include <Eigen/Geometry>
#include <cmath>
#include <sstream>

#include "sim/synthetic/sim_sensor.h"

namespace px::sim {

Status SimBoard::Validate() const {
  std::ostringstream error;
  if (inner_cols < 3 || inner_cols > 25 || inner_cols % 2 == 0) {
    error << "inner_cols " << inner_cols << " is not odd in [3, 25]";
  } else if (inner_rows < 3 || inner_rows > 25 || inner_rows % 2 == 0) {
    error << "inner_rows " << inner_rows << " is not odd in [3, 25]";
  } else if (!(square_m > 0 && square_m <= 1)) {
    error << "square_m " << square_m << " is outside (0, 1]";
  } else if (!(border_m >= 0 && border_m <= 1)) {
    error << "border_m " << border_m << " is outside [0, 1]";
  }
  if (error.str().empty()) return OkStatus();
  return InvalidArgumentError("sim board: " + error.str());
}

std::vector<cv::Point3f> SimBoard::Corners() const {
  std::vector<cv::Point3f> corners;
  for (int j = 0; j < inner_rows; ++j) {
    for (int i = 0; i < inner_cols; ++i) {
      corners.emplace_back(static_cast<float>(i * square_m), static_cast<float>(j * square_m), 0.0f);
    }
  }
  return corners;
}

Scene MakeBoardScene(const SimBoard& board, const Rigid3& rig_from_board) {
  Scene scene;
  scene.name = "board";
  Material checker;
  checker.name = "checker";
  checker.kind = MaterialKind::kChecker;
  checker.bgr_a = {235, 235, 235};
  checker.bgr_b = {20, 20, 20};
  checker.scale_m = board.square_m;
  checker.lit = false;
  Material card;
  card.name = "card";
  card.bgr_a = {235, 235, 235};
  card.lit = false;
  Material backdrop;
  backdrop.name = "backdrop";
  backdrop.kind = MaterialKind::kNoise;
  backdrop.bgr_a = {70, 80, 90};
  backdrop.bgr_b = {150, 140, 130};
  backdrop.scale_m = 0.5;
  scene.materials = {checker, card, backdrop};
  // The squares' centre (a corner, both counts even) sits at the middle inner corner.
  const Eigen::Vector3d centre_on_board(
      0.5 * (board.inner_cols - 1) * board.square_m, 0.5 * (board.inner_rows - 1) * board.square_m, 0.0);
  const Eigen::Matrix3d r = rig_from_board.RotationMatrix();
  Plane squares;
  squares.name = "squares";
  squares.centre_m = rig_from_board * centre_on_board;
  squares.right = r.col(0);
  squares.down = r.col(1);
  squares.normal = -r.col(2);
  squares.width_m = (board.inner_cols + 1) * board.square_m;
  squares.height_m = (board.inner_rows + 1) * board.square_m;
  squares.material = 0;
  Plane white = squares;
  white.name = "card";
  white.centre_m = rig_from_board * (centre_on_board + Eigen::Vector3d(0, 0, 0.002));  // just behind
  white.width_m += 2 * board.border_m;
  white.height_m += 2 * board.border_m;
  white.material = 1;
  scene.planes = {squares, white};
  scene.backdrop = Backdrop{2.0, 2};
  return scene;
}

std::vector<Rigid3> BoardPoses(const SimBoard& board, const SimCameraSpec& spec, int count, uint64_t seed) {
  cv::RNG rng(seed * 7919 + 13);
  const double board_width_m = (board.inner_cols + 1) * board.square_m;
  const double view_width_per_m = spec.tile_width / spec.focal_px;  // metres of view per metre of depth
  const Eigen::Vector3d centre_on_board(
      0.5 * (board.inner_cols - 1) * board.square_m, 0.5 * (board.inner_rows - 1) * board.square_m, 0.0);
  std::vector<Rigid3> poses;
  for (int k = 0; k < count; ++k) {
    const double deg = CV_PI / 180.0;
    const Eigen::Matrix3d r = (Eigen::AngleAxisd(rng.uniform(-35.0, 35.0) * deg, Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(rng.uniform(-35.0, 35.0) * deg, Eigen::Vector3d::UnitX()) *
                               Eigen::AngleAxisd(rng.uniform(-15.0, 15.0) * deg, Eigen::Vector3d::UnitZ()))
                                  .toRotationMatrix();
    const double z = board_width_m / (rng.uniform(0.55, 0.75) * view_width_per_m);
    const double reach = 0.05 * z * view_width_per_m;
    const Eigen::Vector3d centre(rng.uniform(-reach, reach), rng.uniform(-0.75 * reach, 0.75 * reach), z);
    poses.push_back(Rigid3::FromMatrix(r, centre - r * centre_on_board));
  }
  return poses;
}

StatusOr<std::vector<BoardCapture>> RenderBoardCaptures(const SimCameraSpec& spec,
                                                        const SimBoard& board,
                                                        const std::vector<Rigid3>& rig_from_board,
                                                        uint64_t seed) {
  PX_RETURN_IF_ERROR(board.Validate());
  std::vector<BoardCapture> captures;
  for (size_t k = 0; k < rig_from_board.size(); ++k) {
    const Scene scene = MakeBoardScene(board, rig_from_board[k]);
    PX_ASSIGN_OR_RETURN(std::vector<ViewTruth> views, RenderLatticeViews(scene, spec));
    BoardCapture capture;
    capture.sensor_bgr = ComposeSensorBgr(spec, views, DrawExposureGains(spec, seed), CaptureNoiseSeed(seed, k));
    capture.rig_from_board = rig_from_board[k];
    captures.push_back(std::move(capture));
  }
  return captures;
}

}  // namespace px::sim
