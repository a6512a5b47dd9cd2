#include "tools/eval_depth_command.h"

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "eval/depth/depth_eval.h"
#include "pipeline/core/log.h"
#include "tools/depth_option_override.h"
#include "tools/machine_info.h"
#include "tools/progress_bar.h"
#include "tools/run_or_fail.h"

namespace px::cli {
namespace {

struct EvalDepthArgs {
  std::string data;
  std::string sets;
  std::string methods = "ours,sweep,sgbm";
  bool no_sim = false;
  bool json = false;
  int threads = 0;
  double working_scale = 0;  // 0 = the depth options' default
  std::string dump;
  std::vector<std::string> overrides;  // "matching.plane_step_px=0.25"
};

nlohmann::json RunToJson(const eval::DepthMethodRun& run, eval::DepthSetKind kind) {
  nlohmann::json j{{"method", run.method}, {"ok", run.ok}, {"seconds", run.seconds}, {"cpu_seconds", run.cpu_seconds}};
  if (!run.note.empty()) j["note"] = run.note;
  if (!run.ok) {
    j["error"] = run.error;
    return j;
  }
  switch (kind) {
    case eval::DepthSetKind::kLightField:
      j["bad_pix_0.07_percent"] = run.hci.bad_pix_007;
      j["bad_pix_0.03_percent"] = run.hci.bad_pix_003;
      j["mse_x100"] = run.hci.mse_x100;
      j["pixels"] = run.hci.pixels;
      break;
    case eval::DepthSetKind::kStereoPair:
      j["bad_1.0_percent"] = run.stereo.bad_1;
      j["bad_2.0_percent"] = run.stereo.bad_2;
      j["avg_error_px"] = run.stereo.avg_error;
      j["pixels"] = run.stereo.pixels;
      break;
    case eval::DepthSetKind::kSimulated:
      j["median_relative_error"] = run.depth.median_relative;
      j["bad_5_percent"] = run.depth.bad_5_percent;
      j["edge_median_relative_error"] = run.depth.edge_median_relative;
      j["edge_bad_5_percent"] = run.depth.edge_bad_5_percent;
      j["pixels"] = run.depth.pixels;
      j["edge_pixels"] = run.depth.edge_pixels;
      break;
  }
  return j;
}

const char* KindName(eval::DepthSetKind kind) {
  switch (kind) {
    case eval::DepthSetKind::kLightField:
      return "light field";
    case eval::DepthSetKind::kStereoPair:
      return "stereo pair";
    case eval::DepthSetKind::kSimulated:
      return "simulated";
  }
  return "?";
}

void PrintSet(const eval::DepthSetResult& set) {
  std::printf("\n%s  (%s)\n", set.name.c_str(), set.detail.c_str());
  switch (set.kind) {
    case eval::DepthSetKind::kLightField:
      std::printf("  %-12s %10s %10s %10s %8s %8s\n", "method", "BadPix.07", "BadPix.03", "MSEx100", "wall s", "cpu s");
      break;
    case eval::DepthSetKind::kStereoPair:
      std::printf("  %-12s %10s %10s %10s %8s %8s\n", "method", "bad-1.0 %", "bad-2.0 %", "avg px", "wall s", "cpu s");
      break;
    case eval::DepthSetKind::kSimulated:
      std::printf("  %-12s %10s %10s %10s %10s %8s %8s\n",
                  "method",
                  "med rel %",
                  ">5% px %",
                  "edge med %",
                  "edge >5% %",
                  "wall s",
                  "cpu s");
      break;
  }
  for (const eval::DepthMethodRun& run : set.runs) {
    if (!run.ok) {
      std::printf("  %-12s failed: %s\n", run.method.c_str(), run.error.c_str());
      continue;
    }
    switch (set.kind) {
      case eval::DepthSetKind::kLightField:
        std::printf("  %-12s %10.2f %10.2f %10.3f %8.2f %8.2f",
                    run.method.c_str(),
                    run.hci.bad_pix_007,
                    run.hci.bad_pix_003,
                    run.hci.mse_x100,
                    run.seconds,
                    run.cpu_seconds);
        break;
      case eval::DepthSetKind::kStereoPair:
        std::printf("  %-12s %10.2f %10.2f %10.3f %8.2f %8.2f",
                    run.method.c_str(),
                    run.stereo.bad_1,
                    run.stereo.bad_2,
                    run.stereo.avg_error,
                    run.seconds,
                    run.cpu_seconds);
        break;
      case eval::DepthSetKind::kSimulated:
        std::printf("  %-12s %10.2f %10.2f %10.2f %10.2f %8.2f %8.2f",
                    run.method.c_str(),
                    100 * run.depth.median_relative,
                    run.depth.bad_5_percent,
                    100 * run.depth.edge_median_relative,
                    run.depth.edge_bad_5_percent,
                    run.seconds,
                    run.cpu_seconds);
        break;
    }
    std::printf("%s%s\n", run.note.empty() ? "" : "  ", run.note.c_str());
  }
}

Status RunEvalDepth(const EvalDepthArgs& args) {
  eval::DepthEvalOptions options;
  options.data_dir = args.data;
  options.set_filter = args.sets;
  options.simulated = !args.no_sim;
  options.num_threads = args.threads;
  options.dump_dir = args.dump;
  options.run_ours = args.methods.find("ours") != std::string::npos;
  options.run_plane_sweep = args.methods.find("sweep") != std::string::npos;
  options.run_sgbm = args.methods.find("sgbm") != std::string::npos;
  if (!options.run_ours && !options.run_plane_sweep && !options.run_sgbm) {
    return InvalidArgumentError("--methods '" + args.methods + "' names none of ours, sweep, sgbm");
  }
  if (args.working_scale != 0) options.ours.working_scale = args.working_scale;
  options.light_field_defaults = args.working_scale == 0 && args.overrides.empty();
  for (const std::string& text : args.overrides) PX_RETURN_IF_ERROR(ApplyDepthOptionOverride(text, &options.ours));
  options.ours.num_threads = args.threads;
  ProgressBar progress(args.json);
  options.progress = [&](const std::string& set, double fraction) { progress.Update(set, fraction); };
  PX_ASSIGN_OR_RETURN(std::vector<eval::DepthSetResult> results, eval::RunDepthEval(options));
  progress.Finish();
  const MachineInfo machine = ReadMachineInfo();
  if (args.json) {
    nlohmann::json sets = nlohmann::json::array();
    for (const eval::DepthSetResult& set : results) {
      nlohmann::json runs = nlohmann::json::array();
      for (const eval::DepthMethodRun& run : set.runs) runs.push_back(RunToJson(run, set.kind));
      sets.push_back({{"set", set.name}, {"kind", KindName(set.kind)}, {"detail", set.detail}, {"methods", runs}});
    }
    const nlohmann::json out{{"sets", sets},
                             {"peak_rss_mib", PeakRssMiB()},
                             {"machine",
                              {{"cpu", machine.cpu_model},
                               {"cores", machine.cores},
                               {"memory_gib", machine.memory_gib},
                               {"commit", machine.commit}}}};
    std::printf("%s\n", out.dump(2).c_str());
    return OkStatus();
  }
  std::printf("depth against ground truth; machine: %s, %d cores, commit %s\n",
              machine.cpu_model.c_str(),
              machine.cores,
              machine.commit.c_str());
  for (const eval::DepthSetResult& set : results) PrintSet(set);
  std::printf("\npeak RSS %.0f MiB\n", PeakRssMiB());
  return OkStatus();
}

}  // namespace

void AddEvalDepthCommand(CLI::App& eval) {
  auto args = std::make_shared<EvalDepthArgs>();
  CLI::App* depth = eval.add_subcommand(
      "depth",
      "Depth against ground truth: ours, the first plane sweep and OpenCV's StereoSGBM side by side on the HCI light "
      "field (3x3 and 9x9; BadPix, MSE), Middlebury and ETH3D pairs (bad-1, bad-2, average error) and simulated "
      "3x3 / 5x4 lattices (relative depth error, overall and near depth edges)");
  depth->add_option("--data",
                    args->data,
                    "A dataset folder (HCI light field, Middlebury or ETH3D pair) or a folder of them "
                    "(default: ../shared/data, or $PX_DATA_DIR)");
  depth->add_option("--sets", args->sets, "Only sets whose name contains this (e.g. 'hci', 'cones', 'sim/')");
  depth->add_option("--methods", args->methods, "Comma-separated subset of ours, sweep, sgbm")->capture_default_str();
  depth->add_flag("--no-sim", args->no_sim, "Leave out the simulated lattices");
  depth->add_option("--threads", args->threads, "Worker threads (0 = all cores)")->capture_default_str();
  depth
      ->add_option("--working-scale",
                   args->working_scale,
                   "Override our matching resolution, a fraction of the view size in (0, 1] (0 = per set)")
      ->capture_default_str();
  depth->add_option("--option",
                    args->overrides,
                    "Override one of our depth options, name=value as in pipeline/depth/depth_options.h "
                    "(repeatable), e.g. --option matching.plane_step_px=0.5");
  depth->add_option(
      "--dump", args->dump, "Write each method's estimate, the truth and an error picture per set into this folder");
  depth->add_flag("--json", args->json, "Print the figures as JSON (machine-readable)");
  depth->callback(RunOrFail("eval", [args] { return RunEvalDepth(*args); }));
}

}  // namespace px::cli
