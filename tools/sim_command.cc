#include "tools/sim_command.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <vector>

#include "capture/recording.h"
#include "pipeline/core/log.h"
#include "pipeline/core/rig_calibration_json.h"
#include "sim/synthetic/board_scene.h"
#include "sim/synthetic/lens_perturbation.h"
#include "sim/synthetic/sim_camera.h"
#include "sim/synthetic/synthetic_source.h"
#include "tools/run_or_fail.h"
#include "tools/scene_path.h"

namespace px::cli {
namespace {

struct SimArgs {
  std::string scene = "still_life";
  std::string camera = "pop9";
  std::string pixel_format = "RGB888";
  uint64_t seed = 1;
  double noise_sigma = -1;
  double vignetting = -1;
  double exposure_spread = -1;
  double k1 = 0;
  int supersampling = 0;
  double baseline_mm = 0;  // 0 = the preset's
  double focal_px = 0;
  std::vector<int> tile_size;  // {width, height}; empty = the preset's
  std::string output;
  bool ground_truth = false;
  int board_captures = 0;            // > 0: render this many checkerboard captures instead of the scene
  uint64_t perturb_lenses_seed = 0;  // 0 = lenses as calibrated
};

// Depth as 16-bit PNG in millimetres (0 = nothing hit): lossless, viewable, good to 65 m.
Status WriteDepthMm(const std::filesystem::path& path, const cv::Mat& depth_m) {
  cv::Mat depth_mm;
  depth_m.convertTo(depth_mm, CV_16U, 1000.0);
  if (!cv::imwrite(path.string(), depth_mm)) return InternalError("cannot write " + path.string());
  return OkStatus();
}

Status WriteGroundTruth(const std::filesystem::path& dir, const sim::GroundTruth& truth) {
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error) return InternalError("cannot create " + dir.string() + ": " + error.message());
  nlohmann::json views = nlohmann::json::array();
  for (const sim::ViewTruth& view : truth.views) {
    char name[32];
    std::snprintf(name, sizeof(name), "view_%02d", view.id.value);
    if (!cv::imwrite((dir / (std::string(name) + ".png")).string(), view.bgr)) {
      return InternalError("cannot write " + (dir / name).string() + ".png");
    }
    PX_RETURN_IF_ERROR(WriteDepthMm(dir / (std::string(name) + "_depth_mm.png"), view.depth_m));
    views.push_back({{"id", view.id.value},
                     {"image", std::string(name) + ".png"},
                     {"depth_mm_png", std::string(name) + "_depth_mm.png"},
                     {"camera", CameraModelToJson(view.camera)},
                     {"cam_from_rig", Rigid3ToJson(view.cam_from_rig)}});
  }
  nlohmann::json j{{"scene", truth.scene_name},
                   {"exposure_gains", truth.exposure_gains},
                   {"noise_seed", truth.noise_seed},
                   {"rig_calibration", RigCalibrationToJson(truth.rig)},
                   {"views", views}};
  std::ofstream out(dir / "ground_truth.json");
  out << j.dump(2) << "\n";
  if (!out) return InternalError("cannot write " + (dir / "ground_truth.json").string());
  return OkStatus();
}

// `--board N`: N sensor frames of the default 7x5 x 20 mm checkerboard at varied poses, as
// capture_NN.png (raw sensor pixels, BGR) in the output folder, with the rig's true calibration
// (ground_truth_rig.json) and the board poses (board_poses.json) beside them.
Status WriteBoardCaptures(const SimCameraSpec& spec, const SimArgs& args) {
  const sim::SimBoard board;
  const std::vector<Rigid3> poses = sim::BoardPoses(board, spec, args.board_captures, args.seed);
  Logger("sim")->info("rendering {} board captures through {}", poses.size(), spec.name);
  PX_ASSIGN_OR_RETURN(std::vector<sim::BoardCapture> captures, sim::RenderBoardCaptures(spec, board, poses, args.seed));
  const std::filesystem::path dir(args.output);
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error) return InternalError("cannot create " + dir.string() + ": " + error.message());
  nlohmann::json pose_json = nlohmann::json::array();
  for (size_t k = 0; k < captures.size(); ++k) {
    char name[32];
    std::snprintf(name, sizeof(name), "capture_%02zu.png", k);
    if (!cv::imwrite((dir / name).string(), captures[k].sensor_bgr)) {
      return InternalError("cannot write " + (dir / name).string());
    }
    pose_json.push_back({{"image", name}, {"rig_from_board", Rigid3ToJson(captures[k].rig_from_board)}});
  }
  std::ofstream rig(dir / "ground_truth_rig.json");
  rig << RigCalibrationToJsonText(spec.Calibration()) << "\n";
  std::ofstream poses_out(dir / "board_poses.json");
  poses_out << nlohmann::json{{"inner_cols", board.inner_cols},
                              {"inner_rows", board.inner_rows},
                              {"square_m", board.square_m},
                              {"captures", pose_json}}
                   .dump(2)
            << "\n";
  if (!rig || !poses_out) return InternalError("cannot write the ground truth in " + dir.string());
  std::printf("%s\n", std::filesystem::absolute(dir).c_str());
  return OkStatus();
}

Status RunSim(const SimArgs& args) {
  SyntheticSourceOptions options;
  if (args.camera == "pop9") {
    options.camera = SimCameraSpec::Pop9();
  } else if (args.camera == "integral5x4") {
    options.camera = SimCameraSpec::Integral5x4();
  } else {
    return InvalidArgumentError("--camera '" + args.camera + "' is not pop9 or integral5x4");
  }
  auto format = ParsePixelFormat(args.pixel_format);
  if (!format) return InvalidArgumentError("--format '" + args.pixel_format + "' is not a known pixel format");
  options.camera.pixel_format = *format;
  if (args.noise_sigma >= 0) options.camera.noise_sigma = args.noise_sigma;
  if (args.vignetting >= 0) options.camera.vignetting = args.vignetting;
  if (args.exposure_spread >= 0) options.camera.exposure_spread = args.exposure_spread;
  if (args.supersampling > 0) options.camera.supersampling = args.supersampling;
  options.camera.distortion[0] = args.k1;
  if (args.baseline_mm > 0) options.camera.baseline_m = args.baseline_mm / 1000.0;
  if (args.focal_px > 0) options.camera.focal_px = args.focal_px;
  if (args.tile_size.size() == 2) {
    options.camera.tile_width = args.tile_size[0];
    options.camera.tile_height = args.tile_size[1];
  }
  options.camera.perturb_lenses_seed = args.perturb_lenses_seed;
  PX_RETURN_IF_ERROR(options.camera.Validate());
  if (args.board_captures > 0) return WriteBoardCaptures(options.camera, args);
  options.seed = args.seed;
  PX_ASSIGN_OR_RETURN(options.scene_file, ResolveScenePath(args.scene));

  auto log = Logger("sim");
  PX_ASSIGN_OR_RETURN(std::unique_ptr<FrameSource> source, MakeSyntheticSource(options));
  SourceConfig wanted;
  wanted.pixel_format = *format;
  SourceConfig granted;
  PX_ASSIGN_OR_RETURN(ConfigureResult configured, source->Configure(wanted, &granted));
  (void)configured;
  log->info("rendering {} through {} ({})", options.scene_file.string(), options.camera.name, DescribeConfig(granted));
  PX_ASSIGN_OR_RETURN(FrameSet frames, source->Next(std::chrono::milliseconds(600000)));

  Recording recording;
  recording.source = source->Describe();
  recording.frames = std::move(frames);
  recording.created_by = "parallax sim";
  PX_RETURN_IF_ERROR(WriteRecording(args.output, recording));
  if (args.ground_truth) {
    PX_ASSIGN_OR_RETURN(sim::GroundTruth truth, LastGroundTruth(*source));
    PX_RETURN_IF_ERROR(WriteGroundTruth(std::filesystem::path(args.output) / "ground_truth", truth));
  }
  std::printf("%s\n", std::filesystem::absolute(args.output).c_str());
  return OkStatus();
}

}  // namespace

void AddSimCommand(CLI::App& app) {
  auto args = std::make_shared<SimArgs>();
  CLI::App* sim = app.add_subcommand("sim", "Render a synthetic capture of a scene to a recording");
  sim->add_option(
         "--scene", args->scene, "Scene name in sim/scenes (still_life, one_face, two_faces) or a scene JSON path")
      ->capture_default_str();
  sim->add_option("--camera", args->camera, "Camera preset: pop9 (3x3, 640x480 tiles) or integral5x4 (5x4, 320x240)")
      ->capture_default_str();
  sim->add_option("--format", args->pixel_format, "Sensor pixel format: RGB888, BGR888, GRAY8, YUYV, NV12, SRGGB8")
      ->capture_default_str();
  sim->add_option("--seed", args->seed, "Seed of the noise and exposure draws")->capture_default_str();
  sim->add_option("--noise", args->noise_sigma, "Sensor noise sigma in 8-bit levels (default: the preset's)");
  sim->add_option("--vignetting", args->vignetting, "Corner fall-off, 0..1 (default: the preset's)");
  sim->add_option("--exposure-spread", args->exposure_spread, "Per-lens gain spread, 0..0.5 (default: the preset's)");
  sim->add_option("--k1", args->k1, "Radial distortion k1 of every lens")->capture_default_str();
  sim->add_option("--baseline-mm",
                  args->baseline_mm,
                  "Distance between neighbouring lens centres in mm "
                  "(default: the preset's, 25 for pop9, 12 for integral5x4)");
  sim->add_option("--focal-px", args->focal_px, "Focal length in tile pixels (default: the preset's)");
  sim->add_option("--tile", args->tile_size, "Tile size in pixels: --tile 640 480 (default: the preset's)")
      ->expected(2);
  sim->add_option("--supersampling", args->supersampling, "Rays per pixel side, 1..8 (default: the preset's)");
  const LensPerturbation magnitudes;
  char perturb_help[400];
  std::snprintf(perturb_help,
                sizeof(perturb_help),
                "Render through lenses that moved off their calibration, drawn from this seed (0 = none); the "
                "recording keeps the factory calibration, --ground-truth has the true lenses. Per lens, uniform: "
                "focal +-%g %%, principal point +-%g px, rotation +-%g deg about each axis, centre +-%g mm along "
                "each axis",
                100 * magnitudes.focal_relative,
                magnitudes.principal_point_px,
                magnitudes.rotation_deg,
                1000 * magnitudes.centre_m);
  sim->add_option("--perturb-lenses", args->perturb_lenses_seed, perturb_help)->capture_default_str();
  sim->add_flag("--ground-truth",
                args->ground_truth,
                "Also write ground_truth/: clean views, depth (16-bit PNG, mm), cameras and poses");
  sim->add_option("--board",
                  args->board_captures,
                  "Render N captures of a 7x5 (inner corners) x 20 mm checkerboard at varied poses instead of the "
                  "scene: capture_NN.png sensor frames, ground_truth_rig.json and board_poses.json in --output "
                  "(for `parallax calibrate`)");
  sim->add_option("-o,--output", args->output, "Recording folder to create (must not exist or be empty)")->required();
  sim->callback(RunOrFail("sim", [args] { return RunSim(*args); }));
}

}  // namespace px::cli
