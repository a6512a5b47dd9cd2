#include "tools/eval_faces_command.h"

#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "device/face_cascades.h"
#include "eval/faces/faces_eval.h"
#include "eval/faces/sim_face_scenes.h"
#include "pipeline/core/log.h"
#include "tools/machine_info.h"
#include "tools/progress_bar.h"
#include "tools/run_or_fail.h"

namespace px::cli {
namespace {

struct EvalFacesArgs {
  std::string data;
  std::string cascades = device::kDefaultCascadeDir.string();
  bool json = false;
  bool no_sim = false;
  // Overrides of the pipeline's FaceDetectionOptions, for tuning (unset: the pipeline's values).
  double scale_factor = 0;
  int min_neighbors = 0;
  int min_face_px = 0;
  int upscale_below_px = -1;
  std::string profiles;  // "on" / "off"
};

nlohmann::json MatchToJson(const eval::FaceMatch& m) {
  return {{"faces", m.truth},
          {"detections", m.detections},
          {"true_positives", m.true_positives},
          {"false_positives", m.FalsePositives()},
          {"misses", m.Misses()},
          {"precision", m.Precision()},
          {"recall", m.Recall()}};
}

Status RunEvalFaces(const EvalFacesArgs& args) {
  eval::FacesEvalOptions options;
  options.data_dir = args.data;
  FaceDetectionOptions& d = options.detection;
  if (args.scale_factor != 0) d.scale_factor = args.scale_factor;
  if (args.min_neighbors != 0) d.min_neighbors = args.min_neighbors;
  if (args.min_face_px != 0) d.min_face_px = args.min_face_px;
  if (args.upscale_below_px >= 0) d.upscale_below_px = args.upscale_below_px;
  if (!args.profiles.empty()) {
    if (args.profiles != "on" && args.profiles != "off") {
      return InvalidArgumentError("--profiles '" + args.profiles + "' is neither on nor off");
    }
    d.profiles = args.profiles == "on";
  }
  PX_ASSIGN_OR_RETURN(std::shared_ptr<const direct::FaceDetector> detector, device::LoadFaceDetector(args.cascades));
  ProgressBar progress(args.json);
  options.progress = [&](const std::string& image, double fraction) { progress.Update(image, fraction); };
  PX_ASSIGN_OR_RETURN(eval::FacesEvalResult result, eval::RunFacesEval(*detector, options));
  std::vector<eval::FaceImageResult> sim_scenes;
  if (!args.no_sim) {
    progress.Update("sim scenes", 1.0);
    PX_ASSIGN_OR_RETURN(sim_scenes, eval::RunSimFaceScenes(*detector, d, options.min_iou));
  }
  progress.Finish();
  const MachineInfo machine = ReadMachineInfo();
  const nlohmann::json detection_options{{"scale_factor", d.scale_factor},
                                         {"min_neighbors", d.min_neighbors},
                                         {"min_face_px", d.min_face_px},
                                         {"upscale_below_px", d.upscale_below_px},
                                         {"profiles", d.profiles}};
  if (args.json) {
    const auto images_to_json = [](const std::vector<eval::FaceImageResult>& list) {
      nlohmann::json images = nlohmann::json::array();
      for (const eval::FaceImageResult& image : list) {
        nlohmann::json j = MatchToJson(image.match);
        j["image"] = image.file;
        j["ms"] = image.ms;
        images.push_back(j);
      }
      return images;
    };
    const nlohmann::json images = images_to_json(result.images);
    nlohmann::json total = MatchToJson(result.total);
    total["mean_ms_per_image"] = result.mean_ms;
    const nlohmann::json out{
        {"set", "faces_dlib_pascalvoc"},
        {"detector", result.detector},
        {"options", detection_options},
        {"min_iou", options.min_iou},
        {"images", images},
        {"total", total},
        {"sim_scenes", images_to_json(sim_scenes)},
        {"machine", {{"cpu", machine.cpu_model}, {"cores", machine.cores}, {"commit", machine.commit}}}};
    std::printf("%s\n", out.dump(2).c_str());
    return OkStatus();
  }
  std::printf("faces against hand-labelled boxes (faces_dlib_pascalvoc), hit at IoU >= %.2f\n", options.min_iou);
  std::printf("detector: %s; options %s\nmachine: %s, %d cores, commit %s\n\n",
              result.detector.c_str(),
              detection_options.dump().c_str(),
              machine.cpu_model.c_str(),
              machine.cores,
              machine.commit.c_str());
  std::printf("  %-18s %9s %6s %6s %4s %4s %9s %7s %8s\n",
              "image",
              "size",
              "faces",
              "found",
              "hit",
              "FP",
              "precision",
              "recall",
              "ms");
  const auto print_rows = [](const std::vector<eval::FaceImageResult>& list) {
    for (const eval::FaceImageResult& image : list) {
      const eval::FaceMatch& m = image.match;
      std::printf("  %-18s %4dx%-4d %6d %6d %4d %4d %9.2f %7.2f %8.1f\n",
                  image.file.c_str(),
                  image.size.width,
                  image.size.height,
                  m.truth,
                  m.detections,
                  m.true_positives,
                  m.FalsePositives(),
                  m.Precision(),
                  m.Recall(),
                  image.ms);
    }
  };
  print_rows(result.images);
  const eval::FaceMatch& t = result.total;
  std::printf("  %-18s %9s %6d %6d %4d %4d %9.2f %7.2f %8.1f (mean)\n",
              "all",
              "",
              t.truth,
              t.detections,
              t.true_positives,
              t.FalsePositives(),
              t.Precision(),
              t.Recall(),
              result.mean_ms);
  if (!sim_scenes.empty()) {
    std::printf("\nsimulated Pop9 centre lens (sim/scenes; true boxes projected from the scene)\n");
    print_rows(sim_scenes);
  }
  return OkStatus();
}

}  // namespace

void AddEvalFacesCommand(CLI::App& eval) {
  auto args = std::make_shared<EvalFacesArgs>();
  CLI::App* faces = eval.add_subcommand(
      "faces",
      "Face detection against hand-labelled boxes: the product's detector (the pipeline's cascades and options) on "
      "faces_dlib_pascalvoc (4 PASCAL VOC photos, 18 faces); per image and overall faces, detections, true "
      "positives at IoU >= 0.5, precision, recall and time; then the same on the simulated one_face and two_faces "
      "scenes (640x480 centre lens, true boxes from the scene)");
  faces->add_option(
      "--data", args->data, "The folder holding faces_dlib_pascalvoc/ (default: ../shared/data, or $PX_DATA_DIR)");
  faces->add_option("--cascades", args->cascades, "Folder of the OpenCV cascades (Debian package opencv-data)")
      ->capture_default_str();
  faces->add_flag("--json", args->json, "Print the figures as JSON (machine-readable)");
  faces->add_flag("--no-sim", args->no_sim, "Leave out the simulated face scenes (one_face, two_faces at 640x480)");
  faces->add_option("--scale-factor", args->scale_factor, "Override direct.faces.scale_factor, (1, 2] (tuning)");
  faces->add_option("--min-neighbors", args->min_neighbors, "Override direct.faces.min_neighbors, [1, 30] (tuning)");
  faces->add_option("--min-face-px", args->min_face_px, "Override direct.faces.min_face_px, [8, 1024] (tuning)");
  faces->add_option("--upscale-below-px",
                    args->upscale_below_px,
                    "Override direct.faces.upscale_below_px, [0, 4096], 0 = never (tuning)");
  faces->add_option("--profiles", args->profiles, "Override direct.faces.profiles: on or off (tuning)");
  faces->callback(RunOrFail("eval", [args] { return RunEvalFaces(*args); }));
}

}  // namespace px::cli
