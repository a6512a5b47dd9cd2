#include "tools/import_command.h"

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "capture/import_images.h"
#include "capture/recording.h"
#include "pipeline/core/log.h"
#include "tools/run_or_fail.h"

namespace px::cli {
namespace {

struct ImportArgs {
  std::vector<std::string> inputs;
  std::string output;
  std::string lattice;  // "" = photos; "auto" or "RxC": one photo of a lattice of views
};

// One photo holding a lattice of views, as a lattice-frame recording to be split blind.
Status RunImportLattice(const ImportArgs& args) {
  const auto log = Logger("import");
  if (args.inputs.size() != 1) {
    return InvalidArgumentError("--lattice takes one photo of a lattice, got " + std::to_string(args.inputs.size()));
  }
  PX_ASSIGN_OR_RETURN(LatticeHint hint, ParseLatticeSize(args.lattice));
  std::vector<std::string> warnings;
  PX_ASSIGN_OR_RETURN(Recording recording, RecordingFromLatticePhoto(args.inputs[0], hint, &warnings));
  for (const std::string& warning : warnings) log->warn("{}", warning);
  PX_RETURN_IF_ERROR(WriteRecording(args.output, recording));
  const Frame& frame = recording.frames.frames[0];
  log->info(
      "wrote recording {}: a lattice frame of {}x{} ({}), no rig calibration: split blind when processed",
      args.output,
      frame.image.width,
      frame.image.height,
      hint.rows > 0 ? std::to_string(hint.rows) + "x" + std::to_string(hint.cols) + " tiles" : "lattice found blind");
  std::printf("%s\n", args.output.c_str());
  return OkStatus();
}

Status RunImport(const ImportArgs& args) {
  if (!args.lattice.empty()) return RunImportLattice(args);
  const auto log = Logger("import");
  std::vector<std::filesystem::path> inputs(args.inputs.begin(), args.inputs.end());
  PX_ASSIGN_OR_RETURN(std::vector<std::filesystem::path> files, ListImages(inputs));
  std::vector<std::string> warnings;
  // Files named one by one are the user's choice of views; one folder is taken as one capture.
  const bool one_folder = inputs.size() == 1 && std::filesystem::is_directory(inputs[0]);
  PX_ASSIGN_OR_RETURN(
      Recording recording,
      one_folder ? RecordingFromFolder(inputs[0], files, &warnings) : RecordingFromImages(files, &warnings));
  for (const std::string& warning : warnings) log->warn("{}", warning);
  if (recording.frames.kind == FrameSetKind::kLatticeFrame) {  // one photo alone: a lattice
    PX_RETURN_IF_ERROR(WriteRecording(args.output, recording));
    log->info("wrote recording {}: a lattice frame, no rig calibration: split blind when processed", args.output);
    std::printf("%s\n", args.output.c_str());
    return OkStatus();
  }
  for (size_t i = 0; i < recording.frames.frames.size(); ++i) {
    const Frame& frame = recording.frames.frames[i];
    log->info("view {}: {}x{}, focal {}",
              i,
              frame.image.width,
              frame.image.height,
              frame.focal_length_px > 0 ? std::to_string(static_cast<int>(frame.focal_length_px + 0.5)) + " px (" +
                                              frame.focal_length_source + ")"
                                        : std::string("unknown (self-calibrated)"));
  }
  PX_RETURN_IF_ERROR(WriteRecording(args.output, recording));
  log->info("wrote recording {}: an image set of {} views ({} file(s) read)",
            args.output,
            recording.frames.frames.size(),
            files.size());
  std::printf("%s\n", args.output.c_str());
  return OkStatus();
}

}  // namespace

void AddImportCommand(CLI::App& app) {
  auto args = std::make_shared<ImportArgs>();
  CLI::App* command = app.add_subcommand(
      "import",
      "Make a recording of photos taken by hand from a few places (JPEG, PNG; the EXIF focal length is kept), "
      "a 3D camera's MPO file (each image a view) or a wigglegram's animated GIF or WebP (each frame a "
      "view, repeated frames left out), for `parallax clip`");
  command
      ->add_option(
          "photos",
          args->inputs,
          "Photos, MPO files, animations, or folders of them (sorted by name); at least 2 views in all, or one "
          "photo alone, taken as a lattice of views found blind (as --lattice auto)")
      ->required();
  command->add_option("-o,--output", args->output, "Recording folder to create (must not exist or be empty)")
      ->required();
  command->add_option("--lattice",
                      args->lattice,
                      "The one photo holds a lattice of views (a film scan of a Nishika, Nimslo, ActionSampler or "
                      "Pop9 frame, a multi-lens or wiggle lens's frame, a side-by-side stereo JPEG): auto (found "
                      "blind) or RxC, e.g. 1x4; posed later by structure from motion");
  command->callback(RunOrFail("import", [args]() { return RunImport(*args); }));
}

}  // namespace px::cli
