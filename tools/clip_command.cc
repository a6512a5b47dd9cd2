#include "tools/clip_command.h"

#include <cctype>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "capture/import_images.h"
#include "device/clip_job.h"
#include "device/face_cascades.h"
#include "device/storage/storage_layout.h"
#include "pipeline/core/log.h"
#include "pipeline/direct/shot_file.h"
#include "pipeline/io/durable_file.h"
#include "pipeline/render/gl/render_backend.h"
#include "tools/clip_flags.h"
#include "tools/progress_bar.h"
#include "tools/run_or_fail.h"

namespace px::cli {
namespace {

struct ClipArgs {
  std::string recording;
  std::string output;
  ClipFlags flags;
  bool quiet = false;
};

// --format auto: from the output's extension (.mp4, .gif, .webp; a name ending in '/' or an
// existing folder: png), else mp4.
StatusOr<clip::ClipFormat> ChooseFormat(const ClipArgs& args) {
  if (args.flags.format != "auto") return clip::ParseClipFormat(args.flags.format);
  const std::filesystem::path output(args.output);
  std::error_code ec;
  if (!output.has_filename() || std::filesystem::is_directory(output, ec)) return clip::ClipFormat::kPng;
  for (clip::ClipFormat format : {clip::ClipFormat::kGif, clip::ClipFormat::kWebp}) {
    if (output.extension() == clip::ClipFormatExtension(format)) return format;
  }
  return clip::ClipFormat::kMp4;
}

// A JPEG or PNG file (by its name): one photo, which holds several views only as a lattice.
bool IsSinglePhoto(const std::filesystem::path& path) {
  return std::filesystem::is_regular_file(path) && IsStillPhotoName(path);
}

// A folder without a recording's manifest, read as photos taken by hand, or a file holding
// several views (import_images.h).
StatusOr<Recording> PhotoFolderAsRecording(const std::filesystem::path& folder) {
  StatusOr<std::vector<std::filesystem::path>> photos = ListImages({folder});
  if (!photos.ok()) {
    return NotFoundError(folder.string() +
                         ": neither a recording (no manifest.json), a folder of photos nor a file of views (" +
                         photos.status().message() + ")");
  }
  std::vector<std::string> warnings;
  PX_ASSIGN_OR_RETURN(Recording recording,
                      std::filesystem::is_directory(folder) ? RecordingFromFolder(folder, *photos, &warnings)
                                                            : RecordingFromImages(*photos, &warnings));
  const auto log = Logger("clip");
  for (const std::string& warning : warnings) log->warn("{}", warning);
  if (recording.frames.kind == FrameSetKind::kLatticeFrame) {
    log->info("{}: not a recording; its one photo taken as a lattice of views (found blind)", folder.string());
  } else {
    log->info("{}: not a recording; {} views taken as a hand-held image set",
              folder.string(),
              recording.frames.frames.size());
  }
  return recording;
}

Status RunClip(const ClipArgs& args) {
  PX_ASSIGN_OR_RETURN(const clip::ClipFormat format, ChooseFormat(args));
  PX_ASSIGN_OR_RETURN(device::ClipJobOptions options, ClipJobOptionsFromFlags(args.flags, format));
  LoadFaceDetectorUnlessOff(args.flags, options);
  std::filesystem::path output(args.output);
  if (!output.has_filename()) output = output.parent_path();  // "frames/" names the folder "frames"
  auto log = Logger("clip");
  ProgressBar progress(args.quiet);
  const auto show = [&](const std::string& stage, double fraction) {
    progress.Update(stage, fraction);
    return true;
  };
  // A folder of photos (no manifest) is imported as `parallax import` would, in memory: the
  // photos themselves are the raw capture.
  const std::filesystem::path source(args.recording);
  device::ClipJobReport report;
  if (std::filesystem::exists(source / "manifest.json")) {
    PX_ASSIGN_OR_RETURN(report, device::RunClipJob(source, output, options, show));
  } else if (IsSinglePhoto(source)) {
    // One photo: a lattice of views (a film scan, a multi-lens frame), found blind.
    std::vector<std::string> warnings;
    PX_ASSIGN_OR_RETURN(Recording recording, RecordingFromLatticePhoto(source, LatticeHint{}, &warnings));
    for (const std::string& warning : warnings) log->warn("{}", warning);
    log->info("{}: one photo, taken as a lattice of views (found blind)", source.string());
    PX_ASSIGN_OR_RETURN(report,
                        device::RunClipJob(recording, std::filesystem::absolute(source), output, options, show));
  } else {
    PX_ASSIGN_OR_RETURN(Recording recording, PhotoFolderAsRecording(source));
    PX_ASSIGN_OR_RETURN(report,
                        device::RunClipJob(recording, std::filesystem::absolute(source), output, options, show));
  }
  progress.Finish();
  log->info("shot written to {}", device::ClipShotPathFor(report.clip_path).string());
  for (const std::string& warning : report.pipeline.warnings) log->warn("{}", warning);
  for (const StageTiming& t : report.pipeline.timings) log->info("{:<8} {:8.1f} ms", t.stage, t.ms);
  if (!report.pipeline.render_backend.empty()) {
    log->info("rendered on {} ({})", report.pipeline.render_backend, report.pipeline.render_backend_reason);
  }
  log->info("{} {} frames {}x{}, {:.1f} KiB, {:.1f} ms in all; report {}",
            report.format,
            report.frames_written,
            report.width,
            report.height,
            report.clip_bytes / 1024.0,
            report.total_ms,
            report.report_path.string());
  std::printf("%s\n", report.clip_path.c_str());
  return OkStatus();
}

}  // namespace

void AddClipCommand(CLI::App& app) {
  auto args = std::make_shared<ClipArgs>();
  CLI::App* clip = app.add_subcommand("clip", "Turn a recording into a clip (the offline pipeline)");
  clip->add_option("recording",
                   args->recording,
                   "Recording folder (see capture/FORMAT.md), a folder of hand-held photos (JPEG, PNG) taken as "
                   "an image set, a 3D camera's MPO file or a wigglegram's animated GIF or WebP")
      ->required()
      ->check(CLI::ExistingPath);
  clip->add_option("-o,--output",
                   args->output,
                   "Clip to write (a folder for --format png); its camera path and report (JSON) go beside it")
      ->required();
  AddClipFlags(*clip, args->flags);
  clip->add_flag("-q,--quiet", args->quiet, "No progress bar");
  clip->callback(RunOrFail("clip", [args] { return RunClip(*args); }));
}

}  // namespace px::cli
