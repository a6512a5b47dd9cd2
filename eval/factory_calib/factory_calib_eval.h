// Factory rig calibration (pipeline/calib/rig_calibrator.h) against the simulated rigs' truth:
// board captures rendered through a SimCameraSpec (with distortion), lattice detected and split,
// rig calibrated, compared lens by lens. `parallax eval calib` can print these rows; the tests run
// them on half-size rigs.
#pragma once

#include <string>
#include <vector>

#include "pipeline/calib/rig_calibrator.h"
#include "pipeline/core/rig_calibration.h"
#include "pipeline/core/status.h"
#include "sim/synthetic/board_scene.h"
#include "sim/synthetic/sim_camera.h"

namespace px::eval {

// Largest errors over the lenses.
struct RigCalibrationError {
  double focal_pct = 0;               // |f - f_true| / f_true, fx and fy
  double principal_point_px = 0;      // |(cx, cy) - truth|
  double corner_reprojection_px = 0;  // a tile corner's true pixel, through the found model (all intrinsics)
  double rotation_deg = 0;            // angle of cam_from_rig against the truth's
  double centre_of_baseline = 0;      // lens-centre error / baseline_m
};

// INVALID_ARGUMENT when the rigs differ in lens count or image size.
StatusOr<RigCalibrationError> CompareRigCalibrations(const RigCalibration& truth,
                                                     const RigCalibration& found,
                                                     double baseline_m);

struct FactoryCalibCase {
  std::string name;
  SimCameraSpec spec;
  sim::SimBoard board;
  int captures = 8;
  uint64_t seed = 1;
};

// 3x3 (Pop9) and 5x4 (integral) rigs with barrel distortion, vignetting and noise, at `scale` of
// the presets' tile size (the tests use 0.5), 8 board captures each.
std::vector<FactoryCalibCase> StandardFactoryCalibCases(double scale = 1.0);

// The sim board as the calibrator's board description.
CalibrationBoard ToCalibrationBoard(const sim::SimBoard& board);

struct FactoryCalibRow {
  std::string name;
  RigCalibrationResult result;
  RigCalibrationError error;
  double lattice_ms = 0;  // lattice detection (near the nominal layout), all captures
};

// Renders the captures, detects the lattice near the spec's nominal layout on each (the first
// capture's layout is used for all), splits,
// calibrates and compares. Errors from any step are returned with their context.
StatusOr<FactoryCalibRow> EvaluateFactoryCalibration(const FactoryCalibCase& c);

std::string FormatFactoryCalibRow(const FactoryCalibRow& row);

}  // namespace px::eval
