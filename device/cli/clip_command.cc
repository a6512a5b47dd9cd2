#include "device/cli/clip_command.h"

#include <cstdio>
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
  int crf = 20;
  std::string preset = "veryfast";
  std::string quality = "preview";
  int threads = 0;
  bool quiet = false;
};

Status RunClip(const ClipArgs& args) {
  device::ClipJobOptions options;
  options.pipeline.direct.move = args.move;
  options.pipeline.direct.duration_s = args.duration_s;
  options.pipeline.direct.fps = args.fps;
  options.pipeline.num_threads = args.threads;
  PX_ASSIGN_OR_RETURN(options.pipeline.render.quality, ParseRenderQuality(args.quality));
  options.mp4.crf = args.crf;
  options.mp4.preset = args.preset;
  options.mp4.fps = args.fps;
  PX_RETURN_IF_ERROR(options.Validate());
  ProgressBar progress(args.quiet);
  PX_ASSIGN_OR_RETURN(device::ClipJobReport report,
                      device::RunClipJob(args.recording, args.output, options,
                                         [&](const std::string& stage, double fraction) {
                                           progress.Update(stage, fraction);
                                           return true;
                                         }));
  progress.Finish();
  auto log = Logger("clip");
  for (const std::string& warning : report.pipeline.warnings) log->warn("{}", warning);
  for (const StageTiming& t : report.pipeline.timings) log->info("{:<8} {:8.1f} ms", t.stage, t.ms);
  log->info("{} frames {}x{}, {:.1f} KiB, {:.1f} ms in all; report {}", report.frames_written, report.width,
            report.height, report.clip_bytes / 1024.0, report.total_ms, report.report_path.string());
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
  clip->add_option("-o,--output", args->output, "Clip to write (MP4); its camera path and report go beside it")
      ->required();
  clip->add_option("--move", args->move, "Camera move: auto or establishing_dolly")->capture_default_str();
  clip->add_option("--duration", args->duration_s, "Clip length in seconds")->capture_default_str();
  clip->add_option("--fps", args->fps, "Frames per second")->capture_default_str();
  clip->add_option("--crf", args->crf, "x264 quality, 0..51, lower is better")->capture_default_str();
  clip->add_option("--preset", args->preset, "x264 preset, ultrafast..veryslow")->capture_default_str();
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
