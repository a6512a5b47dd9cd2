#include "tools/eval_render_command.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "eval/render/closeup_eval.h"
#include "eval/render/handheld_eval.h"
#include "eval/render/pan_eval.h"
#include "eval/render/render_eval.h"
#include "pipeline/core/log.h"
#include "sim/synthetic/data_paths.h"
#include "tools/consistent_blend_flags.h"
#include "tools/depth_option_override.h"
#include "tools/machine_info.h"
#include "tools/run_or_fail.h"
#include "tools/scene_path.h"
#include "tools/texture_stretch_flags.h"

namespace px::cli {
namespace {

namespace fs = std::filesystem;

struct EvalRenderArgs {
  std::vector<std::string> data;  // dataset folders or scene files; empty = the standard set
  std::vector<std::string> scenes = {"still_life", "two_faces"};
  std::vector<std::string> groups = {"standard", "closeup"};
  std::vector<std::string> closeup_scenes = eval::CloseUpScenes();
  std::vector<std::string> motion_scenes = {"one_face"};
  std::vector<std::string> depths = {"stage", "truth"};
  std::string quality = "preview";
  double sim_scale = 1.0;
  double soft_z_gamma = RenderOptions().soft_z_gamma_fraction;
  SeamSkirtOptions seam_skirts;
  double viewing_weight_exponent = RenderOptions().viewing_weight_exponent;
  int block_px = LayeredFromDepthOptions().block_px;
  double edge_front_weight = LayeredFromDepthOptions().edge_front_weight;
  bool skip_hci_full_grid = false;
  bool holes_from_other_views = RenderOptions().holes_from_other_views;
  render::BorderHoleFillOptions border_holes = RenderOptions().border_holes;
  ConsistentBlendOptions consistent_blend;
  TextureStretchOptions texture_stretch;
  std::vector<std::string> depth_overrides;  // name=value, as `eval depth --option`
  std::string dump_dir;
  bool json = false;
};

// What a --data argument is, from its layout.
enum class Layout { kSimScene, kHci, kLlff, kUnknown };

Layout DetectLayout(const fs::path& path) {
  if (fs::is_regular_file(path) && path.extension() == ".json") return Layout::kSimScene;
  if (fs::exists(path / "parameters.cfg")) return Layout::kHci;
  if (fs::exists(path / "poses_bounds.npy")) return Layout::kLlff;
  return Layout::kUnknown;
}

Status RunEvalRender(const EvalRenderArgs& args) {
  eval::RenderEvalOptions options;
  PX_ASSIGN_OR_RETURN(options.render.quality, ParseRenderQuality(args.quality));
  options.sim_scale = args.sim_scale;
  options.render.soft_z_gamma_fraction = args.soft_z_gamma;
  options.render.seam_skirts = args.seam_skirts;
  options.render.viewing_weight_exponent = args.viewing_weight_exponent;
  options.layered.block_px = args.block_px;
  options.layered.edge_front_weight = args.edge_front_weight;
  options.hci_full_grid = !args.skip_hci_full_grid;
  options.render.holes_from_other_views = args.holes_from_other_views;
  options.render.border_holes = args.border_holes;
  options.render.consistent_blend = args.consistent_blend;
  options.render.texture_stretch = args.texture_stretch;
  options.dump_dir = args.dump_dir;
  for (const std::string& text : args.depth_overrides) {
    PX_RETURN_IF_ERROR(ApplyDepthOptionOverride(text, &options.depth_stage));
  }
  options.depths.clear();
  for (const std::string& depth : args.depths) {
    PX_ASSIGN_OR_RETURN(eval::EvalDepth source, eval::ParseEvalDepth(depth));
    options.depths.push_back(source);
  }
  if (!args.json) options.progress = [](const std::string& line) { std::fprintf(stderr, "  ... %s\n", line.c_str()); };
  PX_RETURN_IF_ERROR(options.Validate());

  std::vector<std::string> notes;
  std::vector<eval::RenderEvalCase> cases;
  const auto add = [&](StatusOr<std::vector<eval::RenderEvalCase>> result) -> Status {
    if (!result.ok()) return result.status();
    cases.insert(cases.end(), result->begin(), result->end());
    return OkStatus();
  };
  const auto has_group = [&](const std::string& group) {
    return std::find(args.groups.begin(), args.groups.end(), group) != args.groups.end();
  };
  for (const std::string& group : args.groups) {
    if (group != "standard" && group != "closeup" && group != "pan" && group != "handheld" && group != "motion") {
      return InvalidArgumentError("--group '" + group + "' is not one of standard, closeup, pan, handheld, motion");
    }
  }
  std::vector<fs::path> data;
  if (!has_group("standard")) {
    // Other groups only.
  } else if (args.data.empty()) {
    for (const std::string& scene : args.scenes) {
      PX_ASSIGN_OR_RETURN(fs::path file, ResolveScenePath(scene));
      data.push_back(file);
    }
    for (const char* name : {"hci_4dlf_antinous", "llff_fern", "llff_flower"}) {
      const fs::path dir = sim::SharedDataDir() / name;
      if (fs::exists(dir)) {
        data.push_back(dir);
      } else {
        notes.push_back(dir.string() + " is absent: skipped (see ../shared/data/SOURCES.md)");
      }
    }
  } else {
    for (const std::string& item : args.data) {
      const fs::path path(item);
      if (DetectLayout(path) == Layout::kUnknown && !fs::exists(path)) {
        PX_ASSIGN_OR_RETURN(fs::path file, ResolveScenePath(item));  // a bare scene name
        data.push_back(file);
      } else {
        data.push_back(path);
      }
    }
  }
  for (const fs::path& path : data) {
    switch (DetectLayout(path)) {
      case Layout::kSimScene:
        PX_RETURN_IF_ERROR(add(eval::EvaluateSimulatedScene(path, SimCameraSpec::Pop9(), options)));
        PX_RETURN_IF_ERROR(add(eval::EvaluateSimulatedScene(path, SimCameraSpec::Integral5x4(), options)));
        break;
      case Layout::kHci:
        PX_RETURN_IF_ERROR(add(eval::EvaluateHciCentreView(path, options)));
        break;
      case Layout::kLlff:
        PX_RETURN_IF_ERROR(add(eval::EvaluateLlffHeldOut(path, options)));
        break;
      case Layout::kUnknown:
        return InvalidArgumentError("--data '" + path.string() +
                                    "' is neither a scene JSON, an HCI folder (parameters.cfg) nor an LLFF folder "
                                    "(poses_bounds.npy)");
    }
  }
  if (has_group("closeup")) {
    for (const std::string& scene : args.closeup_scenes) {
      PX_ASSIGN_OR_RETURN(fs::path file, ResolveScenePath(scene));
      PX_RETURN_IF_ERROR(add(eval::EvaluateSimulatedCloseUps(file, options)));
    }
  }
  if (has_group("pan")) {
    for (const std::string& scene : args.scenes) {
      PX_ASSIGN_OR_RETURN(fs::path file, ResolveScenePath(scene));
      PX_RETURN_IF_ERROR(add(eval::EvaluateSimulatedPan(file, SimCameraSpec::Pop9(), options)));
      PX_RETURN_IF_ERROR(add(eval::EvaluateSimulatedPan(file, SimCameraSpec::Integral5x4(), options)));
    }
  }
  if (has_group("handheld")) {
    for (const std::string& scene : args.scenes) {
      PX_ASSIGN_OR_RETURN(fs::path file, ResolveScenePath(scene));
      PX_RETURN_IF_ERROR(add(eval::EvaluateSimulatedHandheld(file, options)));
    }
  }

  if (has_group("motion")) {
    for (const std::string& scene : args.motion_scenes) {
      PX_ASSIGN_OR_RETURN(fs::path file, ResolveScenePath(scene));
      PX_RETURN_IF_ERROR(add(eval::EvaluateSimulatedHandheldMotion(file, options)));
    }
  }

  const MachineInfo machine = ReadMachineInfo();
  if (args.json) {
    nlohmann::json rows = nlohmann::json::array();
    for (const eval::RenderEvalCase& c : cases) {
      rows.push_back({{"dataset", c.dataset},
                      {"viewpoint", c.viewpoint},
                      {"width", c.width},
                      {"height", c.height},
                      {"sources", c.num_sources},
                      {"depth", eval::EvalDepthName(c.depth)},
                      {"psnr_db", c.psnr_db},
                      {"ssim", c.ssim},
                      {"psnr_covered_edges_db", c.psnr_covered_edges_db},
                      {"psnr_covered_flat_db", c.psnr_covered_flat_db},
                      {"psnr_holes_db", c.psnr_holes_db},
                      {"hole_ratio", c.hole_ratio},
                      {"hole_score", c.hole_score},
                      {"render_ms", c.render_ms},
                      {"crack_fraction", c.crack_fraction},
                      {"temporal_psnr_db", c.temporal_psnr_db},
                      {"double_image_fraction", c.double_image_fraction}});
    }
    const nlohmann::json result{
        {"backend", "cpu"},
        {"quality", args.quality},
        {"cases", rows},
        {"notes", notes},
        {"machine", {{"cpu", machine.cpu_model}, {"cores", machine.cores}, {"commit", machine.commit}}}};
    std::printf("%s\n", result.dump(2).c_str());
    return OkStatus();
  }
  std::printf("render evaluation: cpu back end, %s quality; machine %s, %d cores, commit %s\n",
              args.quality.c_str(),
              machine.cpu_model.c_str(),
              machine.cores,
              machine.commit.c_str());
  std::printf("%-32s %-35s %-12s %9s %4s %7s %7s %7s %7s %7s %7s %8s %8s %7s %8s\n",
              "dataset",
              "viewpoint",
              "depth",
              "size",
              "srcs",
              "PSNR dB",
              "SSIM",
              "edge dB",
              "flat dB",
              "hole dB",
              "holes %",
              "cracks %",
              "ms/frame",
              "temp dB",
              "double %");
  // Mean PSNR and cracks per kind of dataset (sim, sim close-up, hci, llff) and depth source.
  struct Mean {
    double psnr_db = 0, crack_fraction = 0, temporal_psnr_db = 0;
    int count = 0;
  };
  std::map<std::pair<std::string, std::string>, Mean> means;
  const auto ends_with = [](const std::string& text, const std::string& end) {
    return text.size() > end.size() && text.compare(text.size() - end.size(), end.size(), end) == 0;
  };
  for (const eval::RenderEvalCase& c : cases) {
    const std::string size = std::to_string(c.width) + "x" + std::to_string(c.height);
    const std::string depth(eval::EvalDepthName(c.depth));
    char temporal[16] = "      -", doubled[16] = "       -";
    if (c.temporal_psnr_db >= 0) std::snprintf(temporal, sizeof temporal, "%7.2f", c.temporal_psnr_db);
    if (c.double_image_fraction >= 0) std::snprintf(doubled, sizeof doubled, "%8.3f", 100 * c.double_image_fraction);
    std::printf("%-32s %-35s %-12s %9s %4d %7.2f %7.4f %7.2f %7.2f %7.2f %7.3f %8.3f %8.1f %s %s\n",
                c.dataset.c_str(),
                c.viewpoint.c_str(),
                depth.c_str(),
                size.c_str(),
                c.num_sources,
                c.psnr_db,
                c.ssim,
                c.psnr_covered_edges_db,
                c.psnr_covered_flat_db,
                c.psnr_holes_db,
                100 * c.hole_ratio,
                100 * c.crack_fraction,
                c.render_ms,
                temporal,
                doubled);
    std::string group;
    for (const char* suffix : {" close-up", " pan", " hand-held", " hand-held no EXIF", " hand-held, face turning"}) {
      if (ends_with(c.dataset, suffix)) group = suffix;
    }
    // LLFF scenes each have their published figures: a mean per scene.
    const std::string kind = c.dataset.rfind("llff ", 0) == 0 ? c.dataset : c.dataset.substr(0, c.dataset.find(' '));
    Mean& mean = means[{kind + group, depth}];
    mean.psnr_db += c.psnr_db;
    mean.crack_fraction += c.crack_fraction;
    mean.temporal_psnr_db += c.temporal_psnr_db;
    ++mean.count;
  }
  for (const auto& [key, mean] : means) {
    std::printf("mean PSNR %-14s with %-12s depth: %6.2f dB over %d views",
                key.first.c_str(),
                key.second.c_str(),
                mean.psnr_db / mean.count,
                mean.count);
    if (mean.crack_fraction >= 0) std::printf("; cracks %.3f %%", 100 * mean.crack_fraction / mean.count);
    if (mean.temporal_psnr_db >= 0) std::printf("; temporal %.2f dB", mean.temporal_psnr_db / mean.count);
    std::printf("\n");
  }
  std::printf(
      "edge / flat dB: PSNR over the pixels covered before hole filling within 3 px of a depth jump (the "
      "truth's where known) / elsewhere; hole dB: over the filled holes (0: none); cracks %%: pixels "
      "rendered over 10 %% behind the true depth between two sides on its true surface at most 3 px "
      "apart (-100: no true depth); temp dB (pan): PSNR of each frame-to-frame change against the truth's, "
      "so only errors that come and go between frames count\n");
  for (const std::string& note : notes) std::printf("note: %s\n", note.c_str());
  std::printf(
      "goals: >= 38 dB on the simulated scenes; > 25.17 dB on llff fern and > 27.40 dB on llff flower (NeRF's "
      "published figures; LLFF's are 22.85 and 25.46)\n");
  return OkStatus();
}

}  // namespace

void AddEvalRenderCommand(CLI::App& eval) {
  auto args = std::make_shared<EvalRenderArgs>();
  CLI::App* render = eval.add_subcommand(
      "render",
      "Novel views against ground truth: PSNR, SSIM and hole ratio for simulated scenes (Pop9 3x3 and integral "
      "5x4 lattices, views between, in front of and behind the lenses), the HCI antinous centre view from its "
      "neighbours and the held-out views of LLFF fern and flower");
  render->add_option("--data",
                     args->data,
                     "Dataset to evaluate instead of the standard set (repeatable): a scene name or JSON, an HCI "
                     "light-field folder or an LLFF folder");
  render->add_option("--scene", args->scenes, "Simulated scenes of the standard set")->capture_default_str();
  render
      ->add_option("--depth",
                   args->depths,
                   "Depth sources, each evaluated (repeatable): stage (the product's depth stage, "
                   "ComputeLayeredDepth), truth (the simulator's exact depth: the renderer's own error; sim "
                   "scenes only), sweep (the plain plane sweep the evaluation used before)")
      ->capture_default_str();
  render
      ->add_option("--group",
                   args->groups,
                   "Case groups (repeatable): standard (the data sets above), closeup (the dolly in that "
                   "`parallax clip` plans on --closeup-scene, halfway and at its close-up end, at 640x480, with "
                   "the crack measure), pan (not by default: 16 frames along the lattice plane across a view "
                   "mesh edge on each --scene and lattice, with the temporal PSNR) and handheld (not by default: "
                   "each --scene shot by hand from four places plus three held-out photos, all posed by the "
                   "product's structure from motion, with and without EXIF; the held-out viewpoints rendered "
                   "from the four) and motion (not by default: the hand-held shots of each --motion-scene with its "
                   "face plane turning and moving between them, each held-out view scored against the face as "
                   "the nearest shot saw it, double images measured)")
      ->capture_default_str();
  render->add_option("--motion-scene", args->motion_scenes, "Scenes of the motion group (with a plane named face)")
      ->capture_default_str();
  render->add_option("--closeup-scene", args->closeup_scenes, "Scenes of the closeup group")->capture_default_str();
  render->add_option("--quality", args->quality, "preview or offline")->capture_default_str();
  render
      ->add_option("--soft-z-gamma",
                   args->soft_z_gamma,
                   "Soft z-buffer gamma as a fraction of the scene's depth range rho, (0, 0.5) (the paper: 0.1)")
      ->capture_default_str();
  render
      ->add_option("--seam-skirt-max-step",
                   args->seam_skirts.max_step,
                   "Seam skirts: touching segments whose planes differ by less than this fraction of inverse depth "
                   "are one surface whose seam is closed, [0, 1); 0 = off")
      ->capture_default_str();
  render
      ->add_option("--seam-skirt-min-step",
                   args->seam_skirts.min_step,
                   "Seam skirts: touching segments whose planes differ by less than this fraction of inverse depth "
                   "cannot part visibly and get no skirt, [0, max step)")
      ->capture_default_str();
  render
      ->add_option("--seam-skirt-weight",
                   args->seam_skirts.weight,
                   "Seam skirts: the weight of a neighbour's skirt texel, (0, 1]")
      ->capture_default_str();
  render
      ->add_option("--viewing-weight-exponent",
                   args->viewing_weight_exponent,
                   "Viewing weights raised to this power and renormalised, (0, 1] (1: the paper's barycentric "
                   "weights)")
      ->capture_default_str();
  render->add_option("--sim-scale", args->sim_scale, "Scale of the simulated lattices' tiles, (0, 1]")
      ->capture_default_str();
  render
      ->add_option("--option",
                   args->depth_overrides,
                   "Override one of the depth stage's options for --depth stage, name=value as in "
                   "pipeline/depth/depth_options.h (repeatable), e.g. --option segments.refine_iterations=2")
      ->capture_default_str();
  render
      ->add_option("--block-px",
                   args->block_px,
                   "Side of the square segments made from per-pixel depth, [2, 64] (smaller follows curved "
                   "surfaces more closely, more segments to draw)")
      ->capture_default_str();
  render
      ->add_option("--edge-front-weight",
                   args->edge_front_weight,
                   "Front layer's weight at depth jumps in segments made from per-pixel depth, (0, 1]; below 1 "
                   "the far segment extends under the edge as layer 1")
      ->capture_default_str();
  render->add_flag("--no-hci-full-grid",
                   args->skip_hci_full_grid,
                   "HCI: skip rendering from the whole 9x9 (depth for 80 views takes minutes)");
  render
      ->add_option("--holes-from-other-views",
                   args->holes_from_other_views,
                   "Draw holes again from the views the view mesh did not blend there before filling them "
                   "(true, false)")
      ->capture_default_str();
  render
      ->add_option("--border-holes",
                   args->border_holes.enabled,
                   "Fill holes at the frame's border by carrying their inner edge straight out, fading to the "
                   "local mean, before the reverse soft z fills the rest (true, false)")
      ->capture_default_str();
  render
      ->add_option("--border-hole-spread",
                   args->border_holes.spread,
                   "Width of that fade along the border per pixel carried out, [0, 4]")
      ->capture_default_str();
  AddConsistentBlendFlags(*render, &args->consistent_blend);
  AddTextureStretchFlags(*render, &args->texture_stretch);
  render->add_option(
      "--dump", args->dump_dir, "Folder to write each case's render, truth, error map (x4) and coverage to");
  render->add_flag("--json", args->json, "Print the figures as JSON (machine-readable)");
  render->callback(RunOrFail("eval", [args] { return RunEvalRender(*args); }));
}

}  // namespace px::cli
