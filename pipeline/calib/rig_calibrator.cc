#include "pipeline/calib/rig_calibrator.h"

#include <Eigen/SVD>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <sstream>

#include "pipeline/core/stage_clock.h"

namespace px {
namespace {

std::string TileName(const LatticeLayout& layout, int view) {
  return "tile " + std::to_string(view) + " (row " + std::to_string(layout.tiles[view].row) + ", col " +
         std::to_string(layout.tiles[view].col) + ")";
}

// The tile nearest the lattice's centre: poses chain through it, so it should see the most.
int CentreView(const LatticeLayout& layout) {
  const cv::Point2d centre(0.5 * layout.sensor_width, 0.5 * layout.sensor_height);
  int best = 0;
  for (int v = 1; v < layout.NumViews(); ++v) {
    if (cv::norm(TileCentre(layout.tiles[v]) - centre) < cv::norm(TileCentre(layout.tiles[best]) - centre)) best = v;
  }
  return best;
}

struct TileBoards {
  std::vector<int> captures;                      // where the board was found
  std::vector<std::vector<cv::Point2f>> corners;  // per such capture
  CameraModel camera;
  double rms_px = 0;
};

Rigid3 RigidFromCv(const cv::Mat& r, const cv::Mat& t) {
  Eigen::Matrix3d rotation;
  Eigen::Vector3d translation;
  cv::cv2eigen(r, rotation);
  cv::cv2eigen(t, translation);
  return Rigid3::FromMatrix(rotation, translation);
}

// The rotation nearest (Frobenius) to the mean of `rotations`.
Eigen::Matrix3d MeanRotation(const std::vector<Eigen::Matrix3d>& rotations) {
  Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
  for (const Eigen::Matrix3d& r : rotations) sum += r;
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(sum, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d r = svd.matrixU() * svd.matrixV().transpose();
  if (r.determinant() < 0) {
    Eigen::Matrix3d u = svd.matrixU();
    u.col(2) *= -1;
    r = u * svd.matrixV().transpose();
  }
  return r;
}

}  // namespace

Status RigCalibratorOptions::Validate() const {
  PX_RETURN_IF_ERROR(board.Validate());
  std::ostringstream error;
  if (min_boards_per_tile < 3 || min_boards_per_tile > 100) {
    error << "min_boards_per_tile " << min_boards_per_tile << " is outside [3, 100]";
  } else if (!(warn_rms_px > 0 && warn_rms_px <= 10)) {
    error << "warn_rms_px " << warn_rms_px << " is outside (0, 10]";
  }
  if (error.str().empty()) return OkStatus();
  return InvalidArgumentError("rig calibrator options: " + error.str());
}

std::string RigCalibrationReport::Summary() const {
  double worst = 0, worst_pose = 0;
  for (const TileCalibrationFigures& t : tiles) {
    worst = std::max(worst, t.rms_px);
    worst_pose = std::max(worst_pose, t.pose_rms_px);
  }
  char text[256];
  std::snprintf(text,
                sizeof(text),
                "%zu tiles from %d captures: board RMS up to %.3f px, pose RMS up to %.3f px, %zu warnings, %.0f ms",
                tiles.size(),
                captures,
                worst,
                worst_pose,
                warnings.size(),
                ms);
  return text;
}

StatusOr<RigCalibrationResult> CalibrateRig(const std::vector<std::vector<cv::Mat>>& tiles_by_capture,
                                            const LatticeLayout& layout,
                                            const RigCalibratorOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  PX_RETURN_IF_ERROR(options.Validate());
  PX_RETURN_IF_ERROR(layout.Validate().WithContext("rig calibration"));
  const int captures = static_cast<int>(tiles_by_capture.size());
  const int views = layout.NumViews();
  if (captures < options.min_boards_per_tile) {
    return InvalidArgumentError("rig calibration: too few captures: " + std::to_string(captures) + ", need at least " +
                                std::to_string(options.min_boards_per_tile) + " (the board at varied poses)");
  }
  for (int k = 0; k < captures; ++k) {
    if (static_cast<int>(tiles_by_capture[k].size()) != views) {
      return InvalidArgumentError("rig calibration: capture " + std::to_string(k) + " has " +
                                  std::to_string(tiles_by_capture[k].size()) + " tiles, the lattice " +
                                  std::to_string(views));
    }
  }
  // Board corners in every tile of every capture (independent: in parallel).
  std::vector<StatusOr<std::vector<cv::Point2f>>> found(captures * views, NotFoundError("not searched"));
  cv::parallel_for_(cv::Range(0, captures * views), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      found[i] = DetectBoardCorners(tiles_by_capture[i / views][i % views], options.board);
    }
  });
  const std::vector<cv::Point3f> board = options.board.Corners();
  std::vector<TileBoards> tiles(views);
  RigCalibrationResult result;
  RigCalibrationReport& report = result.report;
  report.captures = captures;
  for (int v = 0; v < views; ++v) {
    TileBoards& t = tiles[v];
    for (int k = 0; k < captures; ++k) {
      if (found[k * views + v].ok()) {
        t.captures.push_back(k);
        t.corners.push_back(*found[k * views + v]);
      }
    }
    if (static_cast<int>(t.captures.size()) < options.min_boards_per_tile) {
      return NotFoundError("rig calibration: " + TileName(layout, v) + ": board found in only " +
                           std::to_string(t.captures.size()) + " of " + std::to_string(captures) + " captures, need " +
                           std::to_string(options.min_boards_per_tile) + " (" + found[v].status().message() +
                           " in capture 0)");
    }
  }
  // Intrinsics per tile.
  cv::parallel_for_(cv::Range(0, views), [&](const cv::Range& range) {
    for (int v = range.start; v < range.end; ++v) {
      TileBoards& t = tiles[v];
      const cv::Size size = tiles_by_capture[0][v].size();
      std::vector<std::vector<cv::Point3f>> object(t.corners.size(), board);
      cv::Mat k, d;
      std::vector<cv::Mat> rvecs, tvecs;
      const int flags =
          (options.fit_k3 ? 0 : cv::CALIB_FIX_K3) | (options.fit_tangential ? 0 : cv::CALIB_ZERO_TANGENT_DIST);
      t.rms_px = cv::calibrateCamera(object, t.corners, size, k, d, rvecs, tvecs, flags);
      t.camera.width = size.width;
      t.camera.height = size.height;
      t.camera.fx = k.at<double>(0, 0);
      t.camera.fy = k.at<double>(1, 1);
      t.camera.cx = k.at<double>(0, 2);
      t.camera.cy = k.at<double>(1, 2);
      for (int i = 0; i < 5; ++i) t.camera.distortion[i] = d.at<double>(i);
    }
  });
  // Poses: each tile against the reference through the captures both saw.
  const int ref = CentreView(layout);
  report.reference_view = ref;
  std::vector<Rigid3> cam_from_ref(views);
  std::vector<TileCalibrationFigures> figures(views);
  for (int v = 0; v < views; ++v) {
    TileCalibrationFigures& f = figures[v];
    f.view = v;
    f.boards_found = static_cast<int>(tiles[v].captures.size());
    f.rms_px = tiles[v].rms_px;
    if (v == ref) {
      f.shared_with_reference = f.boards_found;
      continue;
    }
    std::vector<std::vector<cv::Point2f>> in_v, in_ref;
    for (size_t a = 0; a < tiles[v].captures.size(); ++a) {
      for (size_t b = 0; b < tiles[ref].captures.size(); ++b) {
        if (tiles[v].captures[a] == tiles[ref].captures[b]) {
          in_v.push_back(tiles[v].corners[a]);
          in_ref.push_back(tiles[ref].corners[b]);
        }
      }
    }
    f.shared_with_reference = static_cast<int>(in_v.size());
    if (in_v.empty()) {
      return NotFoundError("rig calibration: " + TileName(layout, v) + " never saw the board in the same capture as " +
                           TileName(layout, ref) + ", so its pose in the rig is unknown");
    }
    std::vector<std::vector<cv::Point3f>> object(in_v.size(), board);
    cv::Mat k_v(tiles[v].camera.CvK()), d_v = tiles[v].camera.CvDistortion();
    cv::Mat k_r(tiles[ref].camera.CvK()), d_r = tiles[ref].camera.CvDistortion();
    cv::Mat r, t, e, fm;
    // x_v = R x_ref + T: v's camera from the reference camera.
    f.pose_rms_px = cv::stereoCalibrate(
        object, in_ref, in_v, k_r, d_r, k_v, d_v, tiles_by_capture[0][v].size(), r, t, e, fm, cv::CALIB_FIX_INTRINSIC);
    cam_from_ref[v] = RigidFromCv(r, t);
  }
  // The rig frame: origin at the mean lens centre, axes the mean lens orientation.
  std::vector<Eigen::Matrix3d> rotations;
  Eigen::Vector3d mean_centre = Eigen::Vector3d::Zero();
  for (const Rigid3& p : cam_from_ref) {
    rotations.push_back(p.RotationMatrix());
    mean_centre += CameraCentre(p);
  }
  mean_centre /= views;
  const Eigen::Matrix3d ref_from_rig_rotation = MeanRotation(rotations).transpose();
  const Rigid3 ref_from_rig = Rigid3::FromMatrix(ref_from_rig_rotation, mean_centre);
  RigCalibration& rig = result.rig;
  rig.rig_name = options.rig_name;
  rig.lattice = layout;
  for (int v = 0; v < views; ++v) {
    rig.lenses.push_back({tiles[v].camera, cam_from_ref[v] * ref_from_rig});
    if (figures[v].rms_px > options.warn_rms_px || figures[v].pose_rms_px > options.warn_rms_px) {
      char text[200];
      std::snprintf(text,
                    sizeof(text),
                    "%s: board RMS %.2f px, pose RMS %.2f px (above %.2f)",
                    TileName(layout, v).c_str(),
                    figures[v].rms_px,
                    figures[v].pose_rms_px,
                    options.warn_rms_px);
      report.warnings.push_back(text);
    }
  }
  report.tiles = figures;
  PX_RETURN_IF_ERROR(rig.Validate().WithContext("rig calibration result"));
  report.ms = MsSince(start);
  return result;
}

}  // namespace px
