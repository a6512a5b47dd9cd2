#include "tools/eval_calib_command.h"

#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "eval/calib/calib_eval.h"
#include "pipeline/core/log.h"
#include "sim/synthetic/data_paths.h"
#include "tools/machine_info.h"
#include "tools/run_or_fail.h"

namespace px::cli {
namespace {

struct EvalCalibArgs {
  std::string data;  // a data folder; default ../shared/data
  bool json = false;
  bool no_sim = false;   // skip the simulated rigs
  bool no_data = false;  // skip the data folders
  uint64_t seed = 3;     // lens perturbation seed of the simulated rigs
};

nlohmann::json ToJson(const eval::CalibEvalRow& row) {
  nlohmann::json out{{"set", row.set},
                     {"method", row.method},
                     {"reference", row.reference},
                     {"views_total", row.views_total},
                     {"views_registered", row.views_registered},
                     {"rms_px", row.rms_px},
                     {"time_ms", row.time_ms},
                     {"note", row.note}};
  if (row.has_reference) {
    out["rotation_max_deg"] = row.rotation_max_deg;
    out["rotation_mean_deg"] = row.rotation_mean_deg;
    out["centre_max_relative"] = row.centre_max_relative;
    out["focal_max_percent"] = row.focal_max_percent;
  }
  out["focal_observable"] = row.focal_observable;
  out["max_view_rotation_deg"] = row.max_view_rotation_deg;
  return out;
}

void PrintTable(const std::vector<eval::CalibEvalRow>& rows) {
  std::printf("%-40s %-26s %-6s %5s %9s %9s %8s %7s %8s %9s\n",
              "set",
              "method",
              "ref",
              "views",
              "rot max",
              "rot mean",
              "centre",
              "focal",
              "RMS px",
              "time ms");
  std::printf("%-40s %-26s %-6s %5s %9s %9s %8s %7s %8s %9s\n", "", "", "", "", "deg", "deg", "xbase", "%", "", "");
  for (const eval::CalibEvalRow& row : rows) {
    char views[16];
    std::snprintf(views, sizeof(views), "%d/%d", row.views_registered, row.views_total);
    if (row.has_reference) {
      // A self-calibrated focal length without rotation between the views is no measurement.
      char focal[16];
      std::snprintf(focal, sizeof(focal), row.focal_observable ? "%.2f" : "n/o", row.focal_max_percent);
      std::printf("%-40s %-26s %-6s %5s %9.3f %9.3f %8.3f %7s %8.3f %9.0f\n",
                  row.set.c_str(),
                  row.method.c_str(),
                  row.reference.c_str(),
                  views,
                  row.rotation_max_deg,
                  row.rotation_mean_deg,
                  row.centre_max_relative,
                  focal,
                  row.rms_px,
                  row.time_ms);
    } else {
      std::printf("%-40s %-26s %-6s %5s %9s %9s %8s %7s %8.3f %9.0f\n",
                  row.set.c_str(),
                  row.method.c_str(),
                  row.reference.c_str(),
                  views,
                  "-",
                  "-",
                  "-",
                  "-",
                  row.rms_px,
                  row.time_ms);
    }
  }
  for (const eval::CalibEvalRow& row : rows) {
    if (!row.note.empty()) std::printf("note: %s (%s): %s\n", row.set.c_str(), row.method.c_str(), row.note.c_str());
  }
}

Status RunEvalCalib(const EvalCalibArgs& args) {
  const auto progress = [](const std::string& message) { std::fprintf(stderr, "eval calib: %s\n", message.c_str()); };
  std::vector<eval::CalibEvalRow> rows;
  if (!args.no_sim) {
    const std::pair<const char*, SimCameraSpec> rigs[] = {{"sim 3x3 (Pop9) perturbed", SimCameraSpec::Pop9()},
                                                          {"sim 5x4 perturbed", SimCameraSpec::Integral5x4()}};
    for (const auto& [name, spec] : rigs) {
      const std::string set = std::string(name) + " seed " + std::to_string(args.seed);
      progress(set + ": rendering and refining");
      PX_ASSIGN_OR_RETURN(std::vector<eval::CalibEvalRow> sim_rows, eval::EvalSimulatedRig(set, spec, args.seed));
      rows.insert(rows.end(), sim_rows.begin(), sim_rows.end());
    }
  }
  if (!args.no_data) {
    const std::filesystem::path dir = args.data.empty() ? sim::SharedDataDir() : std::filesystem::path(args.data);
    StatusOr<std::vector<eval::CalibEvalRow>> data_rows = eval::EvalDataFolder(dir, progress);
    if (!data_rows.ok()) {
      if (!args.data.empty()) return data_rows.status();
      progress("data sets skipped: " + data_rows.status().ToString());
    } else {
      rows.insert(rows.end(), data_rows->begin(), data_rows->end());
    }
  }
  const MachineInfo machine = ReadMachineInfo();
  if (args.json) {
    nlohmann::json json_rows = nlohmann::json::array();
    for (const eval::CalibEvalRow& row : rows) json_rows.push_back(ToJson(row));
    const nlohmann::json out{{"rows", json_rows},
                             {"seed", args.seed},
                             {"machine",
                              {{"cpu", machine.cpu_model},
                               {"cores", machine.cores},
                               {"memory_gib", machine.memory_gib},
                               {"commit", machine.commit}}}};
    std::printf("%s\n", out.dump(2).c_str());
  } else {
    std::printf("calibration against references; machine: %s, %d cores, commit %s\n",
                machine.cpu_model.c_str(),
                machine.cores,
                machine.commit.c_str());
    PrintTable(rows);
  }
  return OkStatus();
}

}  // namespace

void AddEvalCalibCommand(CLI::App& eval) {
  auto args = std::make_shared<EvalCalibArgs>();
  CLI::App* calib = eval.add_subcommand(
      "calib",
      "Calibration figures: rotation error (deg), camera-centre error (of the baseline), focal error (%), "
      "reprojection RMS (px), views registered and time, on simulated 3x3 and 5x4 rigs with perturbed lenses "
      "(factory vs refined) and on the data sets (HCI central 3x3, Middlebury templeSparseRing, LLFF fern, "
      "hand-held photo folders) by structure from motion; poses compared after a similarity alignment");
  calib->add_option("--data",
                    args->data,
                    "Data folder: one set (HCI, LLFF, Middlebury multi-view, or a folder of photos) or a folder of "
                    "sets (default: ../shared/data)");
  calib->add_flag("--json", args->json, "Print the figures as JSON (machine-readable)");
  calib->add_flag("--no-sim", args->no_sim, "Skip the simulated rigs");
  calib->add_flag("--no-data", args->no_data, "Skip the data folders (simulated rigs only)");
  calib->add_option("--seed", args->seed, "Lens perturbation seed of the simulated rigs")->capture_default_str();
  calib->callback(RunOrFail("eval", [args] { return RunEvalCalib(*args); }));
}

}  // namespace px::cli
