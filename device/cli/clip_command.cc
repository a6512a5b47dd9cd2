#include "device/cli/clip_command.h"

#include <cstdio>
#include <filesystem>
#include <memory>

#include "device/cli/progress_bar.h"
#include "device/clip_job.h"
#include "pipeline/core/log.h"

namespace px::cli {
namespace {

struct ClipArgs {
  std::string recording;
  std::string output;
  std::string move = "auto";
  double duration_s = 5.0;
  double fps = 30.0;
  std::string format = "auto";
  int crf = 20;
  std::string preset = "veryfast";
  int loop_count = 0;
  int webp_quality = 80;
  std::string quality = "preview";
  int threads = 0;
  bool quiet = false;
};

// --format auto: from the output's extension (.mp4, .gif, .webp; a name ending in '/' or an
// existing folder: png), else mp4.
StatusOr<clip::ClipFormat> ChooseFormat(const ClipArgs& args) {
  if (args.format != "auto") return clip::ParseClipFormat(args.format);
  const std::filesystem::path output(args.output);
  std::error_code ec;
  if (!output.has_filename() || std::filesystem::is_directory(output, ec)) return clip::ClipFormat::kPng;
  for (clip::ClipFormat format : {clip::ClipFormat::kGif, clip::ClipFormat::kWebp}) {
    if (output.extension() == clip::ClipFormatExtension(format)) return format;
  }
  return clip::ClipFormat::kMp4;
}

Status RunClip(const ClipArgs& args) {
  device::ClipJobOptions options;
  PX_ASSIGN_OR_RETURN(options.clip.format, ChooseFormat(args));
  std::filesystem::path output(args.output);
  if (!output.has_filename()) output = output.parent_path();  // "frames/" names the folder "frames"
  options.pipeline.direct.move = args.move;
  options.pipeline.direct.duration_s = args.duration_s;
  options.pipeline.direct.fps = args.fps;
  options.pipeline.num_threads = args.threads;
  options.clip.crf = args.crf;
  options.clip.preset = args.preset;
  options.clip.fps = args.fps;
  options.clip.loop_count = args.loop_count;
  options.clip.webp_quality = args.webp_quality;
  PX_ASSIGN_OR_RETURN(options.pipeline.render.quality, ParseRenderQuality(args.quality));
  PX_RETURN_IF_ERROR(options.Validate());
  ProgressBar progress(args.quiet);
  PX_ASSIGN_OR_RETURN(device::ClipJobReport report,
                      device::RunClipJob(args.recording, output, options,
                                         [&](const std::string& stage, double fraction) {
                                           progress.Update(stage, fraction);
                                           return true;
                                         }));
  progress.Finish();
  auto log = Logger("clip");
  for (const std::string& warning : report.pipeline.warnings) log->warn("{}", warning);
  for (const StageTiming& t : report.pipeline.timings) log->info("{:<8} {:8.1f} ms", t.stage, t.ms);
  log->info("{} {} frames {}x{}, {:.1f} KiB, {:.1f} ms in all; report {}", report.format, report.frames_written,
            report.width, report.height, report.clip_bytes / 1024.0, report.total_ms, report.report_path.string());
  std::printf("%s\n", report.clip_path.c_str());
  return OkStatus();
}

}  // namespace

void AddClipCommand(CLI::App& app) {
  auto args = std::make_shared<ClipArgs>();
  CLI::App* clip = app.add_subcommand("clip", "Turn a recording into a clip (the offline pipeline)");
  clip->add_option("recording", args->recording, "Recording folder (see sim/replay/FORMAT.md)")
      ->required()
      ->check(CLI::ExistingDirectory);
  clip->add_option("-o,--output", args->output,
                   "Clip to write (a folder for --format png); its camera path and report (JSON) go beside it")
      ->required();
  clip->add_option("--move", args->move, "Camera move: auto or establishing_dolly")->capture_default_str();
  clip->add_option("--duration", args->duration_s, "Clip length in seconds")->capture_default_str();
  clip->add_option("--fps", args->fps, "Frames per second")->capture_default_str();
  clip->add_option("--format", args->format,
                   "mp4 (H.264), gif or webp (looping animations), png (a folder of frames), or auto: from the "
                   "output's extension (.mp4, .gif, .webp; a folder: png), else mp4")
      ->check(CLI::IsMember({"auto", "mp4", "gif", "webp", "png"}))
      ->capture_default_str();
  clip->add_option("--crf", args->crf, "mp4: x264 quality, 0..51, lower is better")->capture_default_str();
  clip->add_option("--preset", args->preset, "mp4: x264 preset, ultrafast..veryslow")->capture_default_str();
  clip->add_option("--loop", args->loop_count, "gif, webp: times the animation plays, 0 = forever")
      ->capture_default_str();
  clip->add_option("--webp-quality", args->webp_quality, "webp: lossy quality, 0..100")->capture_default_str();
  clip->add_option("--quality", args->quality,
                   "Render quality: preview (paper 6.1, real time) or offline (6.2: soft z over all segments, "
                   "exemplar inpainting, synthetic-aperture depth of field)")
      ->capture_default_str();
  clip->add_option("--threads", args->threads, "Worker threads, 0 = all cores")->capture_default_str();
  clip->add_flag("-q,--quiet", args->quiet, "No progress bar");
  clip->callback([args]() {
    Status status = RunClip(*args);
    if (!status.ok()) {
      Logger("clip")->error("{}", status.ToString());
      throw CLI::RuntimeError(1);
    }
  });
}

}  // namespace px::cli
