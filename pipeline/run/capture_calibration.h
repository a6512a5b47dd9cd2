// Calibration of a capture, the pipeline's first stages: a lattice frame is checked against the
// rig calibration's layout (or its lattice found blind), split into tiles and calibrated by the
// factory calibration refined per shot; an image set (or a lattice with no rig calibration) is
// posed by structure from motion. Bad frames are salvaged where they honestly can be.
#pragma once

#include <string>
#include <vector>

#include "pipeline/calib/calib_options.h"
#include "pipeline/calib/rig_refinement_options.h"
#include "pipeline/calib/sfm_options.h"
#include "pipeline/core/frame_set.h"
#include "pipeline/core/rig_calibration.h"
#include "pipeline/core/status.h"
#include "pipeline/core/view.h"
#include "pipeline/lattice/lattice_options.h"
#include "pipeline/run/pipeline.h"

namespace px {

// Views with the calibration they came from and the depth range they support.
struct CalibratedViews {
  std::vector<View> views;
  double depth_min_m = 0;
  double depth_max_m = 0;
  std::string calibration;  // PipelineReport::calibration
  // Whether distances are in metres: a rig calibration's baselines are; structure from motion's
  // scale is a guess (its median depth), so nothing is judged by a size in metres there.
  bool metric_scale = false;
  std::string summary;
};

// Splits the lattice frame and makes the views, timing both stages ("lattice", "calib" in
// `timings`); image sets go through structure from motion instead. A lattice frame without a rig
// calibration has its lattice found blind with `lattice` (its size when known, its tiles'
// orientation). What was worked around is in `warnings`.
StatusOr<CalibratedViews> CalibrateCapture(const FrameSet& capture,
                                           const RigCalibration& rig,
                                           const CalibOptions& calib,
                                           const calib::RigRefinementOptions& refinement,
                                           const calib::SfmOptions& sfm,
                                           std::vector<std::string>* warnings,
                                           std::vector<StageTiming>* timings,
                                           const LatticeOptions& lattice = {});

// "frame i" or the frame's file name, for warnings that name a frame.
std::string FrameName(const FrameSet& capture, size_t index);

}  // namespace px
