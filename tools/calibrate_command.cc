#include "tools/calibrate_command.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "capture/recording.h"
#include "pipeline/calib/rig_calibrator.h"
#include "pipeline/core/log.h"
#include "pipeline/core/rig_calibration_json.h"
#include "pipeline/io/image_file.h"
#include "pipeline/lattice/lattice_detector.h"
#include "pipeline/lattice/split_lattice.h"
#include "tools/run_or_fail.h"

namespace px::cli {
namespace {

struct CalibrateArgs {
  std::vector<std::string> captures;
  std::string output;
  std::vector<int> board = {7, 5};
  double square_mm = 20.0;
  std::string prior;  // rig JSON whose lattice is the prior
  std::string name = "factory";
  std::string orientation = "rotated180";
  bool fit_k3 = false;
  bool fit_tangential = false;
};

struct LoadedCapture {
  cv::Mat bgr;
  std::optional<LatticeLayout> prior;  // from a recording's rig calibration
};

// A recording folder (its first frame; its rig's lattice as the prior) or an image file of the
// raw sensor frame (EXIF orientation ignored: the sensor's pixels as they lie).
StatusOr<LoadedCapture> LoadCapture(const std::filesystem::path& path) {
  LoadedCapture capture;
  if (std::filesystem::is_directory(path)) {
    PX_ASSIGN_OR_RETURN(Recording recording, ReadRecording(path));
    if (recording.frames.frames.empty()) return InvalidArgumentError("recording " + path.string() + " has no frames");
    PX_ASSIGN_OR_RETURN(capture.bgr, ToBgr(recording.frames.frames[0].image));
    if (recording.source.rig && recording.source.rig->lattice.rows > 0) capture.prior = recording.source.rig->lattice;
    return capture;
  }
  ImageDecodeOptions decode;
  decode.apply_orientation = false;
  PX_ASSIGN_OR_RETURN(capture.bgr, DecodeImageFile(path, decode));
  return capture;
}

Status RunCalibrate(const CalibrateArgs& args) {
  auto log = Logger("calibrate");
  if (args.board.size() != 2) return InvalidArgumentError("--board wants two numbers: inner corners across and down");
  RigCalibratorOptions options;
  options.board.inner_cols = args.board[0];
  options.board.inner_rows = args.board[1];
  options.board.square_m = args.square_mm / 1000.0;
  options.rig_name = args.name;
  options.fit_k3 = args.fit_k3;
  options.fit_tangential = args.fit_tangential;
  PX_RETURN_IF_ERROR(options.Validate());
  LatticeOptions lattice_options;
  PX_ASSIGN_OR_RETURN(lattice_options.orientation, ParseTileOrientation(args.orientation));
  std::optional<LatticeLayout> prior;
  if (!args.prior.empty()) {
    std::ifstream in(args.prior);
    if (!in) return NotFoundError("--prior " + args.prior + " cannot be read");
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    PX_ASSIGN_OR_RETURN(RigCalibration rig, RigCalibrationFromJsonText(text));
    prior = rig.lattice;
  }
  std::vector<std::vector<cv::Mat>> tiles_by_capture;
  LatticeLayout layout;
  for (size_t k = 0; k < args.captures.size(); ++k) {
    PX_ASSIGN_OR_RETURN(LoadedCapture capture, LoadCapture(args.captures[k]));
    // The lattice: near the given prior, else near the recording's, else found on the first
    // capture and searched near it on the others.
    const LatticeLayout* near = prior ? &*prior : capture.prior ? &*capture.prior : k > 0 ? &layout : nullptr;
    StatusOr<LatticeDetection> detection = DetectLattice(capture.bgr, lattice_options, near);
    if (!detection.ok()) return detection.status().WithContext(args.captures[k]);
    log->info("{}: {}", args.captures[k], detection->report.Summary());
    if (k == 0) layout = detection->layout;
    PX_ASSIGN_OR_RETURN(std::vector<cv::Mat> tiles, SplitLattice(capture.bgr, layout));
    tiles_by_capture.push_back(std::move(tiles));
  }
  PX_ASSIGN_OR_RETURN(RigCalibrationResult result, CalibrateRig(tiles_by_capture, layout, options));
  std::printf("tile  boards  board RMS px  pose boards  pose RMS px   fx       fy       cx      cy      k1       k2\n");
  for (const TileCalibrationFigures& t : result.report.tiles) {
    const CameraModel& c = result.rig.lenses[t.view].camera;
    std::printf("%4d  %6d  %12.3f  %11d  %11.3f  %7.2f  %7.2f  %6.2f  %6.2f  %7.4f  %7.4f\n",
                t.view,
                t.boards_found,
                t.rms_px,
                t.shared_with_reference,
                t.pose_rms_px,
                c.fx,
                c.fy,
                c.cx,
                c.cy,
                c.distortion[0],
                c.distortion[1]);
  }
  for (const std::string& warning : result.report.warnings) log->warn("{}", warning);
  std::ofstream out(args.output);
  out << RigCalibrationToJsonText(result.rig) << "\n";
  if (!out) return InternalError("cannot write " + args.output);
  std::printf("%s\n%s\n", result.report.Summary().c_str(), std::filesystem::absolute(args.output).c_str());
  return OkStatus();
}

}  // namespace

void AddCalibrateCommand(CLI::App& app) {
  auto args = std::make_shared<CalibrateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "calibrate",
      "Factory rig calibration: from captures of a checkerboard seen through every lens, find the lattice, "
      "calibrate each tile's intrinsics and distortion and its pose in the rig, and write the rig calibration JSON");
  cmd->add_option("captures",
                  args->captures,
                  "Board captures: recording folders or raw sensor images (PNG/JPEG; EXIF orientation ignored), "
                  "at least 3, the board at varied poses and fully inside every tile")
      ->required();
  cmd->add_option("-o,--output", args->output, "Rig calibration JSON to write")->required();
  cmd->add_option("--board", args->board, "Board inner corners across and down, e.g. --board 7 5")
      ->expected(2)
      ->capture_default_str();
  cmd->add_option("--square-mm", args->square_mm, "Side of one board square in mm (sets the rig's scale)")
      ->capture_default_str();
  cmd->add_option("--prior",
                  args->prior,
                  "A rig calibration JSON whose lattice the captures should show "
                  "(searched near; otherwise the lattice is found on the first capture)");
  cmd->add_option("--name", args->name, "rig_name written into the JSON")->capture_default_str();
  cmd->add_option("--orientation",
                  args->orientation,
                  "How tiles lie on the sensor when no prior says: upright, rotated180, mirrored_x, mirrored_y")
      ->capture_default_str();
  cmd->add_flag("--fit-k3", args->fit_k3, "Also fit the sixth-order radial term k3");
  cmd->add_flag("--fit-tangential", args->fit_tangential, "Also fit tangential distortion p1, p2");
  cmd->callback(RunOrFail("calibrate", [args] { return RunCalibrate(*args); }));
}

}  // namespace px::cli
