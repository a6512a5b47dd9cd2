#include "tools/eval_real_command.h"

#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "device/face_cascades.h"
#include "eval/real/leave_one_out.h"
#include "eval/real/path_eval.h"
#include "eval/real/real_set.h"
#include "pipeline/core/log.h"
#include "pipeline/render/render_options.h"
#include "sim/synthetic/data_paths.h"
#include "tools/consistent_blend_flags.h"
#include "tools/depth_option_override.h"
#include "tools/machine_info.h"
#include "tools/run_or_fail.h"
#include "tools/texture_stretch_flags.h"

namespace px::cli {
namespace {

namespace fs = std::filesystem;

struct EvalRealArgs {
  std::vector<std::string> data;  // sets; empty = the standard real sets under ../shared/data
  std::vector<std::string> parts = {"loo", "path"};
  std::string lattice;  // a lattice photo's size given with --data; "" = auto
  std::string dump_dir;
  int max_photo_side_px = PipelineOptions{}.image_set_max_side_px;
  double duration_s = 5.0;
  double fps = 30.0;
  bool no_faces = false;
  bool no_photometric = false;
  std::string quality = "preview";  // the renderer's, as parallax clip --quality
  std::vector<std::string> depth_overrides;
  ConsistentBlendOptions consistent_blend;
  TextureStretchOptions texture_stretch;
  bool json = false;
  bool markdown = false;
};

// The double-image figures (percent, mean and worst) in `format`, or `unmeasured` for offline frames.
std::string DoubleCell(const eval::PathResult& p, const char* format, const char* unmeasured) {
  if (!p.double_measured) return unmeasured;
  char cell[64];
  std::snprintf(cell, sizeof(cell), format, 100 * p.double_image, 100 * p.double_image_max);
  return cell;
}

// A set's name: its path under the shared data folder where it lies there, else the path given.
std::string SetName(const fs::path& path) {
  const fs::path data = fs::weakly_canonical(sim::SharedDataDir());
  const fs::path full = fs::weakly_canonical(path);
  const fs::path relative = full.lexically_relative(data);
  if (!relative.empty() && *relative.begin() != "..") return relative.generic_string();
  return path.string();
}

nlohmann::json ScoresJson(const eval::ImageScores& s) {
  return {{"psnr_db", s.psnr_db}, {"ssim", s.ssim}, {"psnr_edges_db", s.psnr_edges_db}};
}

struct SetOutcome {
  std::string name;
  std::string layout;
  int views = 0;
  std::string loo_skipped;  // why leave-one-out was not scored ("" when it was)
  std::optional<eval::LeaveOneOutResult> loo;
  std::string path_skipped;
  std::optional<eval::PathResult> path;
};

nlohmann::json OutcomeJson(const SetOutcome& o) {
  nlohmann::json j{{"set", o.name}, {"layout", o.layout}, {"views", o.views}};
  if (o.loo) {
    nlohmann::json cases = nlohmann::json::array();
    for (const eval::LeaveOneOutCase& c : o.loo->cases) {
      cases.push_back({{"view", c.view},
                       {"name", c.view_name},
                       {"sources", c.num_sources},
                       {"nearest_view", c.nearest_view},
                       {"ours", ScoresJson(c.ours)},
                       {"nearest", ScoresJson(c.nearest)},
                       {"plane", ScoresJson(c.plane)},
                       {"invented", c.invented},
                       {"edge_band", c.edge_band},
                       {"depth_ms", c.depth_ms},
                       {"render_ms", c.render_ms}});
    }
    j["leave_one_out"] = {{"posed", o.loo->num_posed},
                          {"calibration", o.loo->calibration},
                          {"cases", cases},
                          {"mean",
                           {{"ours", ScoresJson(eval::Means(*o.loo).ours)},
                            {"nearest", ScoresJson(eval::Means(*o.loo).nearest)},
                            {"plane", ScoresJson(eval::Means(*o.loo).plane)},
                            {"invented", eval::Means(*o.loo).invented}}},
                          {"notes", o.loo->notes}};
  } else if (!o.loo_skipped.empty()) {
    j["leave_one_out"] = {{"skipped", o.loo_skipped}};
  }
  if (o.path) {
    const eval::PathResult& p = *o.path;
    j["path"] = {{"mode", p.mode},
                 {"move", p.move},
                 {"reason", p.reason},
                 {"frames", p.frames},
                 {"width", p.width},
                 {"height", p.height},
                 {"measured", p.measured},
                 {"torn", p.torn},
                 {"torn_max", p.torn_max},
                 {"double_image", p.double_measured ? nlohmann::json(p.double_image) : nlohmann::json()},
                 {"double_image_max", p.double_measured ? nlohmann::json(p.double_image_max) : nlohmann::json()},
                 {"flicker", p.flicker},
                 {"flicker_max", p.flicker_max},
                 {"holes", p.holes},
                 {"holes_max", p.holes_max},
                 {"seconds", p.seconds},
                 {"depth_confident", p.depth_confident},
                 {"depth_consistent", p.depth_consistent},
                 {"warnings", p.warnings}};
  } else if (!o.path_skipped.empty()) {
    j["path"] = {{"skipped", o.path_skipped}};
  }
  return j;
}

void PrintOutcomes(const std::vector<SetOutcome>& outcomes) {
  std::printf("\nleave-one-out novel views (PSNR dB / SSIM; edge: PSNR within 3 px of our render's depth edges)\n");
  std::printf("%-52s %5s %5s  %-21s %-21s %-21s %8s\n",
              "set",
              "views",
              "held",
              "ours dB/SSIM/edge",
              "nearest dB/SSIM/edge",
              "plane dB/SSIM/edge",
              "invented");
  for (const SetOutcome& o : outcomes) {
    if (!o.loo) {
      if (!o.loo_skipped.empty()) std::printf("%-52s skipped: %s\n", o.name.c_str(), o.loo_skipped.c_str());
      continue;
    }
    const eval::LeaveOneOutMeans m = eval::Means(*o.loo);
    const eval::ImageScores &ours = m.ours, &nearest = m.nearest, &plane = m.plane;
    const double invented = m.invented;
    std::printf("%-52s %5d %5zu  %6.2f %.3f %6.2f   %6.2f %.3f %6.2f   %6.2f %.3f %6.2f   %7.2f%%\n",
                o.name.c_str(),
                o.views,
                o.loo->cases.size(),
                ours.psnr_db,
                ours.ssim,
                ours.psnr_edges_db,
                nearest.psnr_db,
                nearest.ssim,
                nearest.psnr_edges_db,
                plane.psnr_db,
                plane.ssim,
                plane.psnr_edges_db,
                100 * invented);
  }
  std::printf("\nthe automatic clip (means over its frames, worst frame in brackets)\n");
  std::printf("%-52s %-9s %-20s %-9s %-17s %-17s %-17s %-15s %6s\n",
              "set",
              "mode",
              "move",
              "size",
              "torn %",
              "double %",
              "flicker %",
              "holes %",
              "s");
  for (const SetOutcome& o : outcomes) {
    if (!o.path) {
      if (!o.path_skipped.empty()) std::printf("%-52s failed: %s\n", o.name.c_str(), o.path_skipped.c_str());
      continue;
    }
    const eval::PathResult& p = *o.path;
    const std::string size = std::to_string(p.width) + "x" + std::to_string(p.height);
    if (!p.measured) {
      std::printf("%-52s %-9s %-20s %-9s not measured (not drawn by the 3D renderer) %6.1f\n",
                  o.name.c_str(),
                  p.mode.c_str(),
                  p.move.c_str(),
                  size.c_str(),
                  p.seconds);
      continue;
    }
    std::printf("%-52s %-9s %-20s %-9s %6.3f (%6.3f) %s %6.3f (%6.3f) %5.2f (%5.2f) %6.1f\n",
                o.name.c_str(),
                p.mode.c_str(),
                p.move.c_str(),
                size.c_str(),
                100 * p.torn,
                100 * p.torn_max,
                DoubleCell(p, "%6.3f (%6.3f)", "     - (     -)").c_str(),
                100 * p.flicker,
                100 * p.flicker_max,
                100 * p.holes,
                100 * p.holes_max,
                p.seconds);
  }
  std::printf(
      "\ntorn: thin far gaps (<= 3 px) in a near surface that the sources show unbroken; double: drawn from a "
      "view a more heavily weighted one contradicts, or blended from views whose colours disagree beyond "
      "noise; flicker: changes of over 40 levels between frames once the camera's motion is taken out\n");
}

// The figures as the README's tables (Markdown), with the machine and commit that made them.
void PrintMarkdown(const std::vector<SetOutcome>& outcomes, const MachineInfo& machine, const std::string& quality) {
  std::printf(
      "Leave-one-out novel views: each held-out photo rendered from the others at the pose the product's "
      "own calibration gave it, mean PSNR in dB (SSIM) over the held-out views; edge: PSNR within 3 px of "
      "depth edges. Made by `build/parallax eval real --markdown%s` on %s (%d cores), commit %s.\n\n",
      quality == "preview" ? "" : (" --quality " + quality).c_str(),
      machine.cpu_model.c_str(),
      machine.cores,
      machine.commit.c_str());
  std::printf("| set | views | held out | ours | ours, edges | nearest view | one plane | invented |\n");
  std::printf("|---|---:|---:|---:|---:|---:|---:|---:|\n");
  for (const SetOutcome& o : outcomes) {
    if (!o.loo) {
      std::printf("| %s | %d | - | not scored: %s | | | | |\n", o.name.c_str(), o.views, o.loo_skipped.c_str());
      continue;
    }
    const eval::LeaveOneOutMeans m = eval::Means(*o.loo);
    const eval::ImageScores &ours = m.ours, &nearest = m.nearest, &plane = m.plane;
    const double invented = m.invented;
    std::printf("| %s | %d | %zu | %.2f (%.3f) | %.2f | %.2f (%.3f) | %.2f (%.3f) | %.2f %% |\n",
                o.name.c_str(),
                o.views,
                o.loo->cases.size(),
                ours.psnr_db,
                ours.ssim,
                ours.psnr_edges_db,
                nearest.psnr_db,
                nearest.ssim,
                plane.psnr_db,
                plane.ssim,
                100 * invented);
  }
  std::printf(
      "\nThe automatic clip, means over its frames (worst frame); `-`: a morph or a 2D pan, not drawn by the 3D "
      "renderer, so not measured (double images of a 3D move: offline frames, which do not measure them):\n\n");
  std::printf("| set | made as | move | torn %% | double images %% | flicker %% | holes %% |\n");
  std::printf("|---|---|---|---:|---:|---:|---:|\n");
  for (const SetOutcome& o : outcomes) {
    if (!o.path) {
      std::printf("| %s | failed: %s | | | | | |\n", o.name.c_str(), o.path_skipped.c_str());
      continue;
    }
    const eval::PathResult& p = *o.path;
    if (!p.measured) {
      std::printf("| %s | %s | %s | - | - | - | - |\n", o.name.c_str(), p.mode.c_str(), p.move.c_str());
      continue;
    }
    std::printf("| %s | %s | %s | %.3f (%.3f) | %s | %.3f (%.3f) | %.2f (%.2f) |\n",
                o.name.c_str(),
                p.mode.c_str(),
                p.move.c_str(),
                100 * p.torn,
                100 * p.torn_max,
                DoubleCell(p, "%.3f (%.3f)", "-").c_str(),
                100 * p.flicker,
                100 * p.flicker_max,
                100 * p.holes,
                100 * p.holes_max);
  }
}

Status RunEvalReal(const EvalRealArgs& args) {
  std::vector<fs::path> paths;
  std::vector<std::string> missing;
  if (args.data.empty()) {
    paths = eval::StandardRealSets(sim::SharedDataDir(), &missing);
    if (paths.empty()) {
      return NotFoundError("no real data under " + sim::SharedDataDir().string() +
                           " (see ../shared/data/SOURCES.md); give sets with --data");
    }
  } else {
    for (const std::string& item : args.data) paths.emplace_back(item);
  }
  bool want_loo = false, want_path = false;
  for (const std::string& part : args.parts) {
    if (part == "loo") {
      want_loo = true;
    } else if (part == "path") {
      want_path = true;
    } else {
      return InvalidArgumentError("--part '" + part + "' is not one of loo, path");
    }
  }
  const auto progress = [&](const std::string& line) {
    if (!args.json && !args.markdown) std::fprintf(stderr, "  ... %s\n", line.c_str());
  };
  eval::LeaveOneOutOptions loo;
  loo.max_side_px = args.max_photo_side_px;
  loo.dump_dir = args.dump_dir;
  loo.progress = progress;
  for (const std::string& text : args.depth_overrides) PX_RETURN_IF_ERROR(ApplyDepthOptionOverride(text, &loo.depth));
  PX_ASSIGN_OR_RETURN(loo.render.quality, ParseRenderQuality(args.quality));
  loo.render.consistent_blend = args.consistent_blend;
  loo.render.texture_stretch = args.texture_stretch;
  loo.photometric.enabled = !args.no_photometric;
  eval::PathEvalOptions path;
  path.pipeline.render.quality = loo.render.quality;
  path.pipeline.render.consistent_blend = args.consistent_blend;
  path.pipeline.render.texture_stretch = args.texture_stretch;
  path.pipeline.photometric.enabled = !args.no_photometric;
  path.pipeline.image_set_max_side_px = args.max_photo_side_px;
  path.pipeline.direct.duration_s = args.duration_s;
  path.pipeline.direct.fps = args.fps;
  path.pipeline.depth = loo.depth;
  path.dump_dir = args.dump_dir;
  path.progress = progress;
  if (!args.no_faces) {
    StatusOr<std::shared_ptr<const direct::FaceDetector>> detector = device::LoadFaceDetector();
    if (detector.ok()) {
      path.pipeline.face_detector = *detector;
    } else {
      Logger("eval")->warn("no face detection: {}", detector.status().message());
    }
  }
  PX_RETURN_IF_ERROR(path.pipeline.Validate());

  std::vector<SetOutcome> outcomes;
  int scored = 0;
  for (const fs::path& set_path : paths) {
    SetOutcome outcome;
    outcome.name = SetName(set_path);
    StatusOr<eval::RealSet> set =
        eval::LoadRealSet(set_path, outcome.name, args.lattice.empty() ? "auto" : args.lattice);
    if (!set.ok()) {
      outcome.loo_skipped = outcome.path_skipped = set.status().message();
      outcomes.push_back(outcome);
      continue;
    }
    outcome.layout = set->layout;
    outcome.views = static_cast<int>(set->capture.frames.size());
    if (want_loo) {
      StatusOr<eval::LeaveOneOutResult> result = eval::EvaluateLeaveOneOut(*set, loo);
      if (result.ok()) {
        outcome.loo = std::move(result).value();
        ++scored;
      } else {
        outcome.loo_skipped = result.status().message();
      }
    }
    if (want_path) {
      StatusOr<eval::PathResult> result = eval::EvaluatePath(*set, path);
      if (result.ok()) {
        outcome.path = std::move(result).value();
        ++scored;
      } else {
        outcome.path_skipped = result.status().ToString();
      }
    }
    outcomes.push_back(std::move(outcome));
  }

  const MachineInfo machine = ReadMachineInfo();
  if (args.markdown) {
    PrintMarkdown(outcomes, machine, args.quality);
  } else if (args.json) {
    nlohmann::json sets = nlohmann::json::array();
    for (const SetOutcome& o : outcomes) sets.push_back(OutcomeJson(o));
    const nlohmann::json result{
        {"quality", args.quality},
        {"sets", sets},
        {"missing", missing},
        {"machine", {{"cpu", machine.cpu_model}, {"cores", machine.cores}, {"commit", machine.commit}}}};
    std::printf("%s\n", result.dump(2).c_str());
  } else {
    std::printf("real captures, %s quality: machine %s, %d cores, commit %s\n",
                args.quality.c_str(),
                machine.cpu_model.c_str(),
                machine.cores,
                machine.commit.c_str());
    PrintOutcomes(outcomes);
    for (const std::string& m : missing) std::printf("note: %s is absent: skipped\n", m.c_str());
  }
  if (scored == 0) return FailedPreconditionError("eval real: no set could be scored");
  return OkStatus();
}

}  // namespace

void AddEvalRealCommand(CLI::App& eval) {
  auto args = std::make_shared<EvalRealArgs>();
  CLI::App* real = eval.add_subcommand(
      "real",
      "The product on real captures, where the photos are the truth: each held-out view rendered from the others at "
      "the pose the product's own calibration gave it (LLFF's protocol) against the nearest view and a one-plane "
      "warp of it; and the automatic clip measured along its path (torn pixels, double images, flicker, holes)");
  real->add_option("--data",
                   args->data,
                   "Real sets to score instead of the standard ones under ../shared/data (repeatable): a folder of "
                   "photos, an LLFF folder (poses_bounds.npy), an HCI light-field folder (parameters.cfg), an MPO "
                   "file, an animated GIF or WebP, or one photo of a lattice of views");
  real->add_option("--lattice",
                   args->lattice,
                   "The size of the lattice in the photos given with --data (auto: found blind; RxC, e.g. 1x3); by "
                   "default auto");
  real->add_option("--part", args->parts, "What to run (repeatable): loo (leave-one-out), path (the automatic clip)")
      ->capture_default_str();
  real->add_option("--dump",
                   args->dump_dir,
                   "Folder for the pictures: per held-out view the photo, our render, both baselines and their "
                   "error maps; per set the clip's contact sheet and its torn, double-image and flicker maps");
  real->add_option("--max-photo-side",
                   args->max_photo_side_px,
                   "Photos are processed at this longer side, as `parallax clip` does (0 = full size)")
      ->capture_default_str();
  real->add_option("--duration", args->duration_s, "The automatic clip's length, seconds")->capture_default_str();
  real->add_option("--fps", args->fps, "The automatic clip's frame rate")->capture_default_str();
  real->add_flag("--no-faces", args->no_faces, "No face detection for the automatic clip");
  real->add_flag("--no-photometric",
                 args->no_photometric,
                 "Leave each view's exposure, colour and vignetting as shot (no equalisation to the centre view)");
  real->add_option(
          "--quality",
          args->quality,
          "Render quality, as parallax clip --quality: preview (paper 6.1, the clip's default) or offline (6.2)")
      ->capture_default_str();
  real->add_option("--option",
                   args->depth_overrides,
                   "Override one of the depth stage's options, name=value as in pipeline/depth/depth_options.h "
                   "(repeatable)");
  AddConsistentBlendFlags(*real, &args->consistent_blend);
  AddTextureStretchFlags(*real, &args->texture_stretch);
  real->add_flag("--json", args->json, "Print the figures as JSON (machine-readable)");
  real->add_flag("--markdown", args->markdown, "Print the figures as the README's tables, with the machine and commit");
  real->callback(RunOrFail("eval", [args] { return RunEvalReal(*args); }));
}

}  // namespace px::cli
