#include "eval/depth/depth_eval.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <limits>
#include <opencv2/core/utility.hpp>
#include <sstream>

#include "eval/datasets/eth3d_two_view.h"
#include "eval/datasets/hci_light_field.h"
#include "eval/datasets/middlebury_stereo.h"
#include "eval/depth/depth_images.h"
#include "eval/depth/sgbm_reference.h"
#include "pipeline/calib/make_views.h"
#include "pipeline/core/log.h"
#include "pipeline/core/pixel_format.h"
#include "pipeline/depth/depth_stage.h"
#include "pipeline/depth/plane_sweep.h"
#include "pipeline/depth/working_view.h"
#include "pipeline/lattice/split_lattice.h"
#include "sim/synthetic/data_paths.h"
#include "sim/synthetic/scene_json.h"
#include "sim/synthetic/sim_sensor.h"

namespace px::eval {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

double ProcessCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Times a method: wall and process CPU seconds.
class MethodTimer {
 public:
  MethodTimer() : wall_(Clock::now()), cpu_(ProcessCpuSeconds()) {}
  void Stop(DepthMethodRun* run) const {
    run->seconds = SecondsSince(wall_);
    run->cpu_seconds = ProcessCpuSeconds() - cpu_;
  }

 private:
  Clock::time_point wall_;
  double cpu_;
};

void Dump(const DepthEvalOptions& options,
          const std::string& set,
          const std::string& method,
          const cv::Mat& estimate,
          const cv::Mat& truth,
          double good,
          double bad) {
  if (options.dump_dir.empty()) return;
  const Status status = WriteDepthImages(options.dump_dir, FileStem(set + "_" + method), estimate, truth, good, bad);
  if (!status.ok()) Logger("eval")->warn("{}", status.ToString());
}

cv::Mat InverseDepth(const cv::Mat& depth_m) {
  cv::Mat inverse(depth_m.size(), CV_32F);
  for (int y = 0; y < depth_m.rows; ++y) {
    for (int x = 0; x < depth_m.cols; ++x) {
      const float z = depth_m.at<float>(y, x);
      inverse.at<float>(y, x) = z > 0 ? 1.0f / z : std::numeric_limits<float>::quiet_NaN();
    }
  }
  return inverse;
}

// A multi-view set: views with cameras, the reference views scored, and their ground truth in
// depth (metres).
struct MultiViewSet {
  std::vector<View> views;
  std::vector<int> scored;  // indices into views
  // Views our method computes, the scored ones first (it checks them against each other, as the
  // product computes every view); empty: the scored ones.
  std::vector<int> computed;
  std::vector<cv::Mat> gt_depth_m;  // per scored view
  double min_depth_m = 0;
  double max_depth_m = 0;
};

// Turns depth into the disparity of a rectified partner at (focal * baseline) with an offset.
cv::Mat DisparityFromDepth(const cv::Mat& depth_m, double focal_baseline, double offset) {
  cv::Mat disparity(depth_m.size(), CV_32F);
  for (int y = 0; y < depth_m.rows; ++y) {
    const float* z = depth_m.ptr<float>(y);
    float* d = disparity.ptr<float>(y);
    for (int x = 0; x < depth_m.cols; ++x) {
      d[x] = z[x] > 0 ? static_cast<float>(focal_baseline / z[x] - offset) : std::numeric_limits<float>::quiet_NaN();
    }
  }
  return disparity;
}

cv::Mat DepthFromDisparity(const cv::Mat& disparity, double focal_baseline, double offset) {
  cv::Mat depth(disparity.size(), CV_32F);
  for (int y = 0; y < disparity.rows; ++y) {
    const float* d = disparity.ptr<float>(y);
    float* z = depth.ptr<float>(y);
    for (int x = 0; x < disparity.cols; ++x) {
      const double denominator = d[x] + offset;
      z[x] = std::isfinite(d[x]) && denominator > 0 ? static_cast<float>(focal_baseline / denominator) : 0.0f;
    }
  }
  return depth;
}

// Depth of the scored views from a method that computes depth maps for chosen views.
using MultiViewMethod = std::function<StatusOr<std::vector<cv::Mat>>(const MultiViewSet&)>;

StatusOr<std::vector<cv::Mat>> RunOurs(const MultiViewSet& set, const DepthOptions& base) {
  DepthOptions options = base;
  options.min_depth_m = set.min_depth_m;
  options.max_depth_m = set.max_depth_m;
  PX_ASSIGN_OR_RETURN(
      DepthStageResult result,
      ComputeLayeredDepthForViews(set.views, set.computed.empty() ? set.scored : set.computed, options));
  std::vector<cv::Mat> depths;
  for (size_t i = 0; i < set.scored.size(); ++i) depths.push_back(result.maps[i].depth_m);
  return depths;
}

StatusOr<std::vector<cv::Mat>> RunPlaneSweep(const MultiViewSet& set, const DepthOptions& ours) {
  // The first plane sweep with its own defaults, at our working scale and plane count so that
  // the comparison is between methods, not resolutions.
  PlaneSweepOptions options;
  options.min_depth_m = set.min_depth_m;
  options.max_depth_m = set.max_depth_m;
  options.working_scale = depth::MatchingScale(set.views, ours.working_scale, ours.min_working_width_px);
  options.num_threads = ours.num_threads;
  std::vector<cv::Mat> depths;
  for (int index : set.scored) {
    PX_ASSIGN_OR_RETURN(DepthMap map, ComputePlaneSweepDepthForView(set.views, index, options));
    depths.push_back(map.depth_m);
  }
  return depths;
}

DepthMethodRun TimeMultiView(const std::string& name,
                             const MultiViewSet& set,
                             const MultiViewMethod& method,
                             const std::function<void(const std::vector<cv::Mat>&, DepthMethodRun*)>& score) {
  DepthMethodRun run;
  run.method = name;
  const MethodTimer timer;
  StatusOr<std::vector<cv::Mat>> depths = method(set);
  timer.Stop(&run);
  if (!depths.ok()) {
    run.error = depths.status().ToString();
    return run;
  }
  run.ok = true;
  score(*depths, &run);
  return run;
}

}  // namespace

namespace {

// Our depth stage and the first plane sweep on a set, each as options ask.
void AddMultiViewRuns(const MultiViewSet& set,
                      const DepthEvalOptions& options,
                      const std::function<void(const std::vector<cv::Mat>&, DepthMethodRun*)>& score,
                      DepthSetResult* result) {
  if (options.run_ours) {
    result->runs.push_back(TimeMultiView(
        "ours", set, [&](const MultiViewSet& s) { return RunOurs(s, options.ours); }, score));
  }
  if (options.run_plane_sweep) {
    result->runs.push_back(TimeMultiView(
        "plane sweep", set, [&](const MultiViewSet& s) { return RunPlaneSweep(s, options.ours); }, score));
  }
}

// ---- HCI light fields -------------------------------------------------------------------

DepthSetResult EvaluateLightField(const HciLightField& lf, int radius, const DepthEvalOptions& given) {
  DepthEvalOptions options = given;
  if (options.light_field_defaults) options.ours = LightFieldDepthOptions(given.ours);
  const int side = 2 * radius + 1;
  DepthSetResult result;
  result.name = "hci/" + lf.scene + " " + std::to_string(side) + "x" + std::to_string(side);
  result.kind = DepthSetKind::kLightField;
  const View& centre = lf.views[lf.CentreIndex()];
  result.detail = std::to_string(side * side) + " views " + std::to_string(centre.camera.width) + "x" +
                  std::to_string(centre.camera.height) + ", centre view scored";
  MultiViewSet set;
  set.views = lf.CentreGrid(radius);
  set.scored = {static_cast<int>(set.views.size()) / 2};
  set.gt_depth_m = {lf.GtDepth()};
  // The scene's disparity range (cfg disp_min / disp_max) as depth.
  set.min_depth_m = lf.DepthFromDisparity(lf.disp_max);
  set.max_depth_m = lf.DepthFromDisparity(lf.disp_min);
  const double focal_baseline = lf.focal_px * lf.baseline_m;
  const auto score = [&](const std::vector<cv::Mat>& depths, DepthMethodRun* run) {
    const cv::Mat disparity = DisparityFromDepth(depths[0], focal_baseline, lf.offset_px);
    run->hci = EvaluateHciDisparity(disparity, lf.gt_disparity);
    Dump(options, result.name, run->method, disparity, lf.gt_disparity, 0.07, 0.3);
  };
  AddMultiViewRuns(set, options, score, &result);
  if (options.run_sgbm) {
    // SGBM on the best rectified pair: the centre with each view of its row (mirrored for the
    // views on its left), scored by disparity per grid step; the best-scoring pair is kept.
    DepthMethodRun best;
    best.method = "sgbm";
    const MethodTimer timer;
    cv::Mat best_disparity;
    const int centre_row = lf.rows / 2, centre_col = lf.cols / 2;
    for (int dc = -radius; dc <= radius; ++dc) {
      if (dc == 0) continue;
      const View& other = lf.views[centre_row * lf.cols + centre_col + dc];
      const int steps = std::abs(dc);
      // Disparity d per step moves the partner's content by -dc * d: a rectified pair with
      // disparity steps * d, in [steps * disp_min, steps * disp_max].
      const double lo = steps * lf.disp_min, hi = steps * lf.disp_max;
      SgbmResult sgbm = dc > 0 ? RunSgbm(centre.image, other.image, lo, hi)
                               : RunSgbmRightReference(other.image, centre.image, lo, hi);
      cv::Mat per_step = sgbm.disparity / steps;
      DepthMethodRun run;
      run.method = "sgbm";
      run.ok = true;
      run.hci = EvaluateHciDisparity(per_step, lf.gt_disparity);
      std::ostringstream note;
      note << "pair with view " << other.id.value << " (" << (dc > 0 ? "+" : "") << dc << " columns), "
           << static_cast<int>(std::lround(100 * sgbm.valid_fraction)) << "% valid before filling";
      run.note = note.str();
      if (!best.ok || run.hci.bad_pix_007 < best.hci.bad_pix_007) {
        best = run;
        best_disparity = per_step;
      }
    }
    timer.Stop(&best);
    Dump(options, result.name, "sgbm", best_disparity, lf.gt_disparity, 0.07, 0.3);
    best.note += "; best of " + std::to_string(2 * radius) + " pairs";
    result.runs.push_back(best);
  }
  return result;
}

// ---- Two-view pairs ---------------------------------------------------------------------

DepthSetResult EvaluatePair(const StereoPair& pair, const DepthEvalOptions& options) {
  DepthSetResult result;
  result.name = pair.name;
  result.kind = DepthSetKind::kStereoPair;
  std::ostringstream detail;
  detail << "2 views " << pair.left.image.cols << "x" << pair.left.image.rows << ", left view scored, disparities "
         << pair.min_disparity << ".." << pair.max_disparity << " px";
  result.detail = detail.str();
  MultiViewSet set;
  set.views = {pair.left, pair.right};
  set.scored = {0};
  set.computed = {0, 1};  // both, so that each confirms the other (left-right check and fill)
  set.gt_depth_m = {DepthFromDisparity(pair.gt_disparity, pair.focal_px * pair.baseline_m, 0)};
  set.min_depth_m = pair.DepthFromDisparity(pair.max_disparity);
  set.max_depth_m = pair.DepthFromDisparity(pair.min_disparity);
  const double focal_baseline = pair.focal_px * pair.baseline_m;
  const auto score = [&](const std::vector<cv::Mat>& depths, DepthMethodRun* run) {
    const cv::Mat disparity = DisparityFromDepth(depths[0], focal_baseline, 0);
    run->stereo = EvaluateStereoDisparity(disparity, pair.gt_disparity);
    Dump(options, result.name, run->method, disparity, pair.gt_disparity, 1.0, 2.0);
  };
  AddMultiViewRuns(set, options, score, &result);
  if (options.run_sgbm) {
    DepthMethodRun run;
    run.method = "sgbm";
    const MethodTimer timer;
    const SgbmResult sgbm = RunSgbm(pair.left.image, pair.right.image, pair.min_disparity, pair.max_disparity);
    timer.Stop(&run);
    run.ok = true;
    run.stereo = EvaluateStereoDisparity(sgbm.disparity, pair.gt_disparity);
    Dump(options, result.name, "sgbm", sgbm.disparity, pair.gt_disparity, 1.0, 2.0);
    run.note = std::to_string(static_cast<int>(std::lround(100 * sgbm.valid_fraction))) + "% valid before filling";
    result.runs.push_back(run);
  }
  return result;
}

// ---- Simulated lattices -----------------------------------------------------------------

struct SimulatedSetSpec {
  std::string name;  // "pop9", "integral5x4"
  SimCameraSpec camera;
  std::string scene;
};

// The simulated camera with a real sensor's defects (noise, vignetting, per-lens exposure), as
// the product sees it; the views go through the product's lattice split and calibration.
StatusOr<MultiViewSet> CaptureSimulated(const SimulatedSetSpec& spec) {
  PX_ASSIGN_OR_RETURN(sim::Scene scene, sim::LoadScene(sim::ScenesDir() / (spec.scene + ".json")));
  PX_ASSIGN_OR_RETURN(sim::SensorFrame frame, sim::RenderSensorFrame(scene, spec.camera, /*seed=*/7));
  PX_ASSIGN_OR_RETURN(cv::Mat sensor, ToBgr(frame.sensor));
  PX_ASSIGN_OR_RETURN(std::vector<cv::Mat> tiles, SplitLattice(sensor, frame.truth.rig.lattice));
  MultiViewSet set;
  PX_ASSIGN_OR_RETURN(set.views, MakeViews(tiles, frame.truth.rig, CalibOptions()));
  for (int i = 0; i < static_cast<int>(set.views.size()); ++i) {
    set.scored.push_back(i);
    set.gt_depth_m.push_back(frame.truth.views[i].depth_m);
  }
  set.min_depth_m = frame.truth.rig.nominal_depth_min_m;
  set.max_depth_m = frame.truth.rig.nominal_depth_max_m;
  return set;
}

// Mean of the per-view depth figures.
DepthErrorMetrics MeanDepthMetrics(const std::vector<cv::Mat>& depths, const std::vector<cv::Mat>& truths) {
  DepthErrorMetrics mean;
  for (size_t i = 0; i < depths.size(); ++i) {
    const DepthErrorMetrics m = EvaluateDepth(depths[i], truths[i]);
    const double n = static_cast<double>(depths.size());
    mean.median_relative += m.median_relative / n;
    mean.bad_5_percent += m.bad_5_percent / n;
    mean.edge_median_relative += m.edge_median_relative / n;
    mean.edge_bad_5_percent += m.edge_bad_5_percent / n;
    mean.pixels += m.pixels;
    mean.edge_pixels += m.edge_pixels;
  }
  return mean;
}

DepthSetResult EvaluateSimulated(const SimulatedSetSpec& spec, const DepthEvalOptions& options) {
  DepthSetResult result;
  result.name = "sim/" + spec.name + " " + spec.scene;
  result.kind = DepthSetKind::kSimulated;
  StatusOr<MultiViewSet> captured = CaptureSimulated(spec);
  if (!captured.ok()) {
    result.detail = "capture failed: " + captured.status().ToString();
    return result;
  }
  const MultiViewSet& set = *captured;
  std::ostringstream detail;
  detail << set.views.size() << " views " << spec.camera.tile_width << "x" << spec.camera.tile_height << " ("
         << spec.camera.rows << "x" << spec.camera.cols << ", " << spec.camera.baseline_m * 1000
         << " mm), every view scored (mean)";
  result.detail = detail.str();
  const size_t shown = set.views.size() / 2;  // the view dumped: the centre of the lattice
  const auto score = [&](const std::vector<cv::Mat>& depths, DepthMethodRun* run) {
    run->depth = MeanDepthMetrics(depths, set.gt_depth_m);
    const cv::Mat truth = InverseDepth(set.gt_depth_m[shown]);
    Dump(options, result.name, run->method, InverseDepth(depths[shown]), truth, 0.01, 0.05);
  };
  AddMultiViewRuns(set, options, score, &result);
  if (options.run_sgbm) {
    // Each view with its nearest partner in its row: the one to the right, or to the left for
    // the last column (mirrored). Disparity = focal * baseline / z.
    DepthMethodRun run;
    run.method = "sgbm";
    const MethodTimer timer;
    std::vector<cv::Mat> depths;
    const int cols = spec.camera.cols;
    const double focal_baseline = spec.camera.focal_px * spec.camera.baseline_m;
    const double lo = focal_baseline / set.max_depth_m, hi = focal_baseline / set.min_depth_m;
    for (int i = 0; i < static_cast<int>(set.views.size()); ++i) {
      const bool has_right = (i % cols) + 1 < cols;
      const SgbmResult sgbm = has_right ? RunSgbm(set.views[i].image, set.views[i + 1].image, lo, hi)
                                        : RunSgbmRightReference(set.views[i - 1].image, set.views[i].image, lo, hi);
      depths.push_back(DepthFromDisparity(sgbm.disparity, focal_baseline, 0));
    }
    timer.Stop(&run);
    run.ok = true;
    run.depth = MeanDepthMetrics(depths, set.gt_depth_m);
    Dump(options, result.name, "sgbm", InverseDepth(depths[shown]), InverseDepth(set.gt_depth_m[shown]), 0.01, 0.05);
    run.note = "each view with its row neighbour";
    result.runs.push_back(run);
  }
  return result;
}

// ---- Discovery --------------------------------------------------------------------------

enum class FolderKind { kNone, kLightField, kMiddlebury, kEth3d };

FolderKind KindOf(const fs::path& dir) {
  if (fs::exists(dir / "parameters.cfg") && fs::exists(dir / "input_Cam000.png")) return FolderKind::kLightField;
  if (IsMiddleburyPairDir(dir)) return FolderKind::kMiddlebury;
  if (IsEth3dPairDir(dir)) return FolderKind::kEth3d;
  return FolderKind::kNone;
}

// Set folders at `root` or up to two levels below it, sorted by path.
std::vector<fs::path> FindSetFolders(const fs::path& root) {
  std::vector<fs::path> found;
  if (KindOf(root) != FolderKind::kNone) return {root};
  std::error_code error;
  for (fs::recursive_directory_iterator it(root, error), end; !error && it != end; it.increment(error)) {
    if (!it->is_directory()) continue;
    if (KindOf(it->path()) != FolderKind::kNone) found.push_back(it->path());
    if (it.depth() >= 1) it.disable_recursion_pending();
  }
  std::sort(found.begin(), found.end());
  return found;
}

bool Matches(const std::string& name, const std::string& filter) {
  return filter.empty() || name.find(filter) != std::string::npos;
}

}  // namespace

StatusOr<std::vector<DepthSetResult>> RunDepthEval(const DepthEvalOptions& options) {
  PX_RETURN_IF_ERROR(options.ours.Validate());
  const fs::path root = options.data_dir.empty() ? sim::SharedDataDir() : options.data_dir;
  if (!options.data_dir.empty() && !fs::exists(root))
    return NotFoundError("eval depth: --data " + root.string() + " does not exist");
  int previous_threads = cv::getNumThreads();
  if (options.num_threads > 0) cv::setNumThreads(options.num_threads);

  // Every job is a named set with a function that evaluates it.
  struct Job {
    std::string name;
    std::function<StatusOr<DepthSetResult>()> run;
  };
  std::vector<Job> jobs;
  for (const fs::path& dir : FindSetFolders(root)) {
    switch (KindOf(dir)) {
      case FolderKind::kLightField:
        for (int radius : {1, 4}) {
          const int side = 2 * radius + 1;
          const std::string name =
              "hci/" + dir.filename().string() + " " + std::to_string(side) + "x" + std::to_string(side);
          jobs.push_back({name, [dir, radius, &options]() -> StatusOr<DepthSetResult> {
                            PX_ASSIGN_OR_RETURN(HciLightField lf, LoadHciLightField(dir));
                            if (lf.gt_disparity.empty()) {
                              return NotFoundError(dir.string() + ": no gt_disp_lowres.pfm to score against");
                            }
                            if (lf.rows < 2 * radius + 1 || lf.cols < 2 * radius + 1) {
                              return InvalidArgumentError(dir.string() + ": light field is smaller than " +
                                                          std::to_string(2 * radius + 1) + " views a side");
                            }
                            return EvaluateLightField(lf, radius, options);
                          }});
        }
        break;
      case FolderKind::kMiddlebury: {
        const std::string name = dir.parent_path().filename().string() + "/" + dir.filename().string();
        jobs.push_back({name, [dir, &options]() -> StatusOr<DepthSetResult> {
                          PX_ASSIGN_OR_RETURN(StereoPair pair, LoadMiddleburyPair(dir));
                          return EvaluatePair(pair, options);
                        }});
        break;
      }
      case FolderKind::kEth3d: {
        const std::string name = "eth3d/" + dir.filename().string();
        jobs.push_back({name, [dir, &options]() -> StatusOr<DepthSetResult> {
                          PX_ASSIGN_OR_RETURN(StereoPair pair, LoadEth3dPair(dir));
                          return EvaluatePair(pair, options);
                        }});
        break;
      }
      case FolderKind::kNone:
        break;
    }
  }
  if (options.simulated) {
    SimulatedSetSpec pop9{"pop9", SimCameraSpec::Pop9(), "still_life"};
    SimulatedSetSpec integral{"integral5x4", SimCameraSpec::Integral5x4(), "still_life"};
    for (SimulatedSetSpec* spec : {&pop9, &integral}) {
      // A real sensor's defects: noise, vignetting and lens-to-lens exposure differences.
      spec->camera.noise_sigma = 1.5;
      spec->camera.vignetting = 0.15;
      spec->camera.exposure_spread = 0.08;
      const SimulatedSetSpec copy = *spec;
      jobs.push_back({"sim/" + copy.name + " " + copy.scene,
                      [copy, &options]() -> StatusOr<DepthSetResult> { return EvaluateSimulated(copy, options); }});
    }
  }
  std::erase_if(jobs, [&](const Job& job) { return !Matches(job.name, options.set_filter); });
  if (jobs.empty()) {
    if (options.num_threads > 0) cv::setNumThreads(previous_threads);
    return NotFoundError("eval depth: no set under " + root.string() +
                         (options.set_filter.empty() ? std::string() : " matches '" + options.set_filter + "'"));
  }
  std::vector<DepthSetResult> results;
  for (size_t i = 0; i < jobs.size(); ++i) {
    if (options.progress) options.progress(jobs[i].name, static_cast<double>(i) / jobs.size());
    StatusOr<DepthSetResult> result = jobs[i].run();
    if (!result.ok()) {
      if (options.num_threads > 0) cv::setNumThreads(previous_threads);
      return result.status().WithContext("eval depth: " + jobs[i].name);
    }
    results.push_back(std::move(result).value());
  }
  if (options.progress) options.progress("done", 1.0);
  if (options.num_threads > 0) cv::setNumThreads(previous_threads);
  return results;
}

}  // namespace px::eval
