// A real capture through the whole product, as `parallax clip` makes it (structure from motion,
// depth, the automatic move, the CPU renderer), measured along the path the clip shows, where there
// is no ground truth: torn pixels, double images, flicker and holes per frame (path_measures.h),
// and a contact sheet of the clip's frames.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "eval/real/real_set.h"
#include "pipeline/core/status.h"
#include "pipeline/run/pipeline.h"

namespace px::eval {

struct PathResult {
  std::string set;
  std::string mode;    // "3D move", "morph", "2D pan and zoom"
  std::string move;    // the move's name ("dolly in", ...)
  std::string reason;  // why this move (the direction stage's line)
  int frames = 0;
  int width = 0;
  int height = 0;
  // Whether the clip's frames were drawn by the 3D renderer, which measures them: a morph or a 2D
  // pan is not measured, and its figures below stay 0.
  bool measured = false;
  // Means over the frames and the worst frame.
  double torn = 0, torn_max = 0;
  // Measured by the preview compositor only: offline frames (RenderQuality::kOffline) leave it
  // unmeasured, false here and both figures 0.
  bool double_measured = false;
  double double_image = 0, double_image_max = 0;
  double flicker = 0, flicker_max = 0;
  double holes = 0, holes_max = 0;
  double seconds = 0;  // the whole run, clip included
  // The depth stage's figures over its computed views: pixels with confident depth, and pixels whose
  // depth another view confirms (what the direction stage's trust in depth rests on).
  double depth_confident = 0;
  double depth_consistent = 0;
  std::vector<std::string> warnings;
};

struct PathEvalOptions {
  PipelineOptions pipeline;  // as `parallax clip` sets it; the CPU renderer is used regardless
  int sheet_frames = 12;     // frames on the contact sheet
  // When not empty: <set>_path.png (the contact sheet, with each frame's figures) and, per frame
  // on it, the torn, double-image and flicker maps beside the frame (<set>_path_maps.png).
  std::filesystem::path dump_dir;
  std::function<void(const std::string&)> progress;
};

StatusOr<PathResult> EvaluatePath(const RealSet& set, const PathEvalOptions& options);

}  // namespace px::eval
