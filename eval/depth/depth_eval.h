// `parallax eval depth`: our depth stage, the first plane sweep and OpenCV's StereoSGBM run on
// the same data, scored with each set's own measures (depth_metrics.h), side by side:
//   - HCI 4D light fields (a folder with parameters.cfg): the centre view from the central 3x3
//     views (Pop9-like) and from all 9x9; BadPix 0.07 / 0.03, MSE x 100.
//   - Middlebury 2003 / 2006 and ETH3D two-view pairs: bad-1, bad-2, average error (px).
//   - Simulated 3x3 (Pop9) and 5x4 lattices with exact depth: median relative error and % of
//     pixels off by more than 5 %, overall and within 3 px of depth edges.
// Sets are found under a data folder (../shared/data by default); simulated sets need none.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "eval/depth/depth_metrics.h"
#include "pipeline/core/status.h"
#include "pipeline/depth/depth_options.h"
#include "pipeline/depth/plane_sweep_options.h"

namespace px::eval {

enum class DepthSetKind { kLightField, kStereoPair, kSimulated };

// One method's run on one set.
struct DepthMethodRun {
  std::string method;  // "ours", "plane sweep", "sgbm"
  bool ok = false;
  std::string error;        // when !ok: why the method produced nothing
  double seconds = 0;       // wall time of the method on the set (all the views it computed)
  double cpu_seconds = 0;   // CPU time of the whole process meanwhile (all threads): on a shared
                            // machine, cpu_seconds / cores is what idle cores would have taken
  std::string note;         // e.g. which pair SGBM used and how dense it was before filling
  HciMetrics hci;           // kLightField
  StereoMetrics stereo;     // kStereoPair
  DepthErrorMetrics depth;  // kSimulated
};

struct DepthSetResult {
  std::string name;  // "hci/antinous 3x3", "middlebury_2003_quarter/cones", "sim/pop9 still_life"
  DepthSetKind kind = DepthSetKind::kStereoPair;
  std::string detail;  // views, size, what is scored
  std::vector<DepthMethodRun> runs;
};

struct DepthEvalOptions {
  // Where to look for sets: a set folder itself, or a folder whose sub-folders (two levels) hold
  // sets. Empty: px::sim::SharedDataDir(). A missing folder leaves only the simulated sets.
  std::filesystem::path data_dir;
  std::string set_filter;  // only sets whose name contains this; empty = all
  bool simulated = true;   // include the simulated lattices
  bool run_ours = true;
  bool run_plane_sweep = true;
  bool run_sgbm = true;
  DepthOptions ours;  // depth range is set per set; the rest is used as is, except:
  // Light fields (disparities of a few pixels between neighbours) get matching at full
  // resolution, plane steps of 0.2 px and 16 spread neighbours (see LightFieldDepthOptions,
  // pipeline/depth/depth_options.h), unless this is false (the caller set its own options).
  bool light_field_defaults = true;
  int num_threads = 0;  // 0 = OpenCV's default
  // When set, each method's estimate, the truth and an error picture per set go here
  // (depth_images.h): disparity for light fields and pairs, inverse depth for simulated sets.
  std::filesystem::path dump_dir;
  // Progress: the set being worked on and the fraction of all sets done.
  std::function<void(const std::string& set, double fraction)> progress;
};

// Runs every set found. Fails only when the data folder holds a set that cannot be read (the
// error names it) or when nothing matches the filter; a method that fails on a set is reported
// in its run.
StatusOr<std::vector<DepthSetResult>> RunDepthEval(const DepthEvalOptions& options);

}  // namespace px::eval
