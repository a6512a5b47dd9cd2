#include "eval/factory_calib/factory_calib_eval.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "pipeline/lattice/lattice_detector.h"
#include "pipeline/lattice/split_lattice.h"

namespace px::eval {

StatusOr<RigCalibrationError> CompareRigCalibrations(const RigCalibration& truth,
                                                     const RigCalibration& found,
                                                     double baseline_m) {
  if (truth.NumViews() != found.NumViews()) {
    return InvalidArgumentError("rig comparison: " + std::to_string(found.NumViews()) + " lenses against " +
                                std::to_string(truth.NumViews()) + " in the truth");
  }
  RigCalibrationError e;
  for (int v = 0; v < truth.NumViews(); ++v) {
    const CameraModel& t = truth.lenses[v].camera;
    const CameraModel& f = found.lenses[v].camera;
    if (t.width != f.width || t.height != f.height) {
      return InvalidArgumentError("rig comparison: lens " + std::to_string(v) + " is " + std::to_string(f.width) + "x" +
                                  std::to_string(f.height) + ", the truth's " + std::to_string(t.width) + "x" +
                                  std::to_string(t.height));
    }
    e.focal_pct = std::max({e.focal_pct, 100 * std::abs(f.fx / t.fx - 1), 100 * std::abs(f.fy / t.fy - 1)});
    e.principal_point_px = std::max(e.principal_point_px, std::hypot(f.cx - t.cx, f.cy - t.cy));
    for (const Eigen::Vector2d& corner : {Eigen::Vector2d(0, 0),
                                          Eigen::Vector2d(t.width - 1, 0),
                                          Eigen::Vector2d(0, t.height - 1),
                                          Eigen::Vector2d(t.width - 1, t.height - 1)}) {
      Eigen::Vector2d through_found;
      if (f.Project(t.Unproject(corner), &through_found)) {
        e.corner_reprojection_px = std::max(e.corner_reprojection_px, (through_found - corner).norm());
      }
    }
    const Rigid3& pt = truth.lenses[v].cam_from_rig;
    const Rigid3& pf = found.lenses[v].cam_from_rig;
    e.rotation_deg = std::max(e.rotation_deg, pt.rotation.angularDistance(pf.rotation) * 180.0 / M_PI);
    e.centre_of_baseline = std::max(e.centre_of_baseline, (CameraCentre(pt) - CameraCentre(pf)).norm() / baseline_m);
  }
  return e;
}

CalibrationBoard ToCalibrationBoard(const sim::SimBoard& board) {
  CalibrationBoard b;
  b.inner_cols = board.inner_cols;
  b.inner_rows = board.inner_rows;
  b.square_m = board.square_m;
  return b;
}

std::vector<FactoryCalibCase> StandardFactoryCalibCases(double scale) {
  std::vector<FactoryCalibCase> cases;
  for (SimCameraSpec spec : {SimCameraSpec::Pop9(), SimCameraSpec::Integral5x4()}) {
    spec.tile_width = static_cast<int>(std::lround(spec.tile_width * scale));
    spec.tile_height = static_cast<int>(std::lround(spec.tile_height * scale));
    spec.focal_px *= scale;
    spec.supersampling = 1;
    spec.distortion = {-0.12, 0.03, 0, 0, 0};
    spec.vignetting = 0.3;
    spec.exposure_spread = 0.05;
    spec.noise_sigma = 1.5;
    FactoryCalibCase c;
    c.name = spec.name + (spec.distortion[0] != 0 ? " (barrel k1 -0.12)" : "");
    c.spec = spec;
    cases.push_back(c);
  }
  return cases;
}

StatusOr<FactoryCalibRow> EvaluateFactoryCalibration(const FactoryCalibCase& c) {
  PX_ASSIGN_OR_RETURN(
      std::vector<sim::BoardCapture> captures,
      sim::RenderBoardCaptures(c.spec, c.board, sim::BoardPoses(c.board, c.spec, c.captures, c.seed), c.seed));
  FactoryCalibRow row;
  row.name = c.name;
  std::vector<std::vector<cv::Mat>> tiles_by_capture;
  LatticeLayout layout;
  for (size_t k = 0; k < captures.size(); ++k) {
    // The factory knows the lattice's nominal design: detection searches near it.
    const LatticeLayout nominal = c.spec.Layout();
    StatusOr<LatticeDetection> detection = DetectLattice(captures[k].sensor_bgr, LatticeOptions(), &nominal);
    if (!detection.ok()) return detection.status().WithContext("board capture " + std::to_string(k));
    row.lattice_ms += detection->report.ms;
    if (k == 0) layout = detection->layout;
    PX_ASSIGN_OR_RETURN(std::vector<cv::Mat> tiles, SplitLattice(captures[k].sensor_bgr, layout));
    tiles_by_capture.push_back(std::move(tiles));
  }
  RigCalibratorOptions options;
  options.board = ToCalibrationBoard(c.board);
  options.rig_name = c.spec.name;
  PX_ASSIGN_OR_RETURN(row.result, CalibrateRig(tiles_by_capture, layout, options));
  PX_ASSIGN_OR_RETURN(row.error, CompareRigCalibrations(c.spec.Calibration(), row.result.rig, c.spec.baseline_m));
  return row;
}

std::string FormatFactoryCalibRow(const FactoryCalibRow& row) {
  char text[512];
  std::snprintf(text,
                sizeof(text),
                "%s: focal error %.3f %%, principal point %.2f px, corner reprojection %.2f px, rotation %.4f deg, "
                "centre %.2f %% of the baseline; %s; lattice %.0f ms\n",
                row.name.c_str(),
                row.error.focal_pct,
                row.error.principal_point_px,
                row.error.corner_reprojection_px,
                row.error.rotation_deg,
                100 * row.error.centre_of_baseline,
                row.result.report.Summary().c_str(),
                row.lattice_ms);
  return text;
}

}  // namespace px::eval
