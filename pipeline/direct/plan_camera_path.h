// The direction stage (paper section 4): finds the subjects, chooses the move from the taxonomy
// (4.1), plans its path through valid viewpoints (4.2) with its image effect (4.3), or follows an
// authored shot (4.4), and never leaves the button without a clip: when depth or calibration is
// not trustworthy, or no 3D path holds, it falls back to the best honest clip, a morph between two
// views (4.5) or a flat pan and zoom over the centre view, and says why.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "pipeline/core/coverage_report.h"
#include "pipeline/core/view.h"
#include "pipeline/direct/camera_path.h"
#include "pipeline/direct/face_detector.h"
#include "pipeline/direct/plan_move.h"
#include "pipeline/direct/shot_file.h"
#include "pipeline/direct/subjects.h"
#include "pipeline/direct/view_morph.h"

namespace px {

struct DirectionContext {
  const direct::FaceDetector* face_detector = nullptr;  // null: no face detection (said in the report)
  // Faces found on the centre view beforehand (while depth ran); used when they are for the view
  // the stage takes as its centre, else the detector runs here.
  const direct::DetectedFaces* centre_faces = nullptr;
  // The renderer's Coverage (pipeline/render/scene_renderer.h); empty: no 3D move can be checked,
  // so none is planned.
  CoverageFunction coverage;
  // `coverage` may be called from several threads at once (CpuSceneRenderer's may; a GL back
  // end's may not): the region search then searches its grid's two halves side by side.
  bool coverage_concurrent = false;
  // The earlier stages' verdict: false when calibration or depth cannot be trusted; 3D moves are
  // then not attempted and `distrust_reason` goes into the path's notes.
  bool depth_trusted = true;
  std::string distrust_reason;
  // Whether the views' distances are metres (a rig calibration); false after structure from
  // motion, whose scale is a guess: a face is then not judged by its size in metres.
  bool metric_scale = true;
  const direct::Shot* shot = nullptr;  // an authored shot to follow instead of choosing (4.4)
};

struct DirectionReport {
  std::string detector;            // cascades used, or why no detection ran
  int faces_detected = 0;          // before size checks and the two-largest cut
  int num_subjects = 0;            // subjects the move was chosen for
  std::string choice;              // the taxonomy's choice and why
  std::vector<std::string> notes;  // fallbacks taken and why, subjects dropped, effects dropped
  bool fell_back = false;          // the clip is not what was asked or drawn first
  direct::MovePlanReport plan;     // figures of the 3D plan (zero for flat or morph clips)
  int coverage_probes = 0;         // renderer coverage measurements, all sizes
  double coverage_ms = 0;          // time inside them
  int verify_probes = 0;           // of which at the verify size (search_scale < verify_scale)
  double verify_ms = 0;
  double subjects_ms = 0;      // finding subjects here (without faces found beforehand)
  double faces_before_ms = 0;  // the detection behind DirectionContext::centre_faces, when used
  double total_ms = 0;
  // For a morph: the correspondences, for pipeline/run to render the frames from.
  std::shared_ptr<const direct::ViewMorph> morph;
};

// Plans the clip's path. Errors only for invalid options or no views; every other problem
// becomes a fallback recorded in the path's notes and the report.
StatusOr<CameraPath> PlanCameraPath(const std::vector<View>& views,
                                    const std::vector<DepthMap>& depths,
                                    const DirectOptions& options,
                                    const DirectionContext& context = {},
                                    DirectionReport* report = nullptr);

// Fraction of the view's pixels with confident depth (confidence >= 0.5; without a confidence
// map, with known depth). 0 without a depth map.
double ConfidentDepthFraction(const View& view, const std::vector<DepthMap>& depths);

}  // namespace px
