#include "device/cli/clip_command.h"

#include <cctype>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "device/cli/progress_bar.h"
#include "device/cli/run_or_fail.h"
#include "device/clip_job.h"
#include "device/face_cascades.h"
#include "pipeline/core/durable_file.h"
#include "pipeline/core/log.h"
#include "pipeline/direct/shot_file.h"
#include "pipeline/render/gl/render_backend.h"
#include "sim/replay/import_images.h"

namespace px::cli {
namespace {

struct ClipArgs {
  std::string recording;
  std::string output;
  std::string move = "auto";
  std::string effect = "auto";
  uint64_t seed = 1;
  std::string shot;                   // a shot file (pipeline/direct/SHOT_FORMAT.md)
  std::vector<double> subject_px;     // x y w h, repeated: user subjects in the centre view
  bool no_faces = false;
  double duration_s = 5.0;
  double fps = 30.0;
  std::string style = "once";
  std::string ease = "smooth";
  double hold_s = 0;
  std::string size;               // "WxH"; "" = from --aspect and --height
  std::string aspect = "source";  // "16:9", "9:16", "1:1", "4:5", ... or source
  int height = 0;                 // with --aspect: the output's height; 0 = the capture's
  std::string format = "auto";
  int crf = 20;
  std::string preset = "veryfast";
  int loop_count = 0;
  int webp_quality = 80;
  std::string quality = "preview";
  std::string gl = "auto";
  int threads = 0;
  int max_photo_side_px = PipelineOptions{}.image_set_max_side_px;
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

// A JPEG or PNG file (by its name): one photo, which holds several views only as a lattice.
bool IsSinglePhoto(const std::filesystem::path& path) {
  std::string extension = path.extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return std::filesystem::is_regular_file(path) && (extension == ".jpg" || extension == ".jpeg" || extension == ".png");
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
  PX_ASSIGN_OR_RETURN(Recording recording, RecordingFromImages(*photos, &warnings));
  const auto log = Logger("clip");
  for (const std::string& warning : warnings) log->warn("{}", warning);
  log->info("{}: not a recording; {} views taken as a hand-held image set", folder.string(),
            recording.frames.frames.size());
  return recording;
}

Status RunClip(const ClipArgs& args) {
  device::ClipJobOptions options;
  PX_ASSIGN_OR_RETURN(options.clip.format, ChooseFormat(args));
  std::filesystem::path output(args.output);
  if (!output.has_filename()) output = output.parent_path();  // "frames/" names the folder "frames"
  options.pipeline.direct.move = args.move;
  options.pipeline.direct.effect = args.effect;
  options.pipeline.direct.seed = args.seed;
  if (args.subject_px.size() % 4 != 0) {
    return InvalidArgumentError("--subject: " + std::to_string(args.subject_px.size()) +
                                " numbers, want x y w h for each subject");
  }
  for (size_t i = 0; i + 3 < args.subject_px.size(); i += 4) {
    options.pipeline.direct.subject_boxes_px.emplace_back(args.subject_px[i], args.subject_px[i + 1],
                                                          args.subject_px[i + 2], args.subject_px[i + 3]);
  }
  auto log = Logger("clip");
  if (!args.no_faces) {
    StatusOr<std::shared_ptr<const direct::FaceDetector>> detector = device::LoadFaceDetector();
    if (detector.ok()) {
      options.pipeline.face_detector = *detector;
    } else {
      log->warn("no face detection: {}", detector.status().message());
    }
  }
  if (!args.shot.empty()) {
    PX_ASSIGN_OR_RETURN(std::string text, ReadFileToString(args.shot));
    const nlohmann::json j = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
    if (j.is_discarded()) return InvalidArgumentError("--shot " + args.shot + ": not valid JSON");
    PX_ASSIGN_OR_RETURN(direct::Shot shot, direct::ShotFromJson(j));
    options.pipeline.shot = std::make_shared<const direct::Shot>(std::move(shot));
  }
  options.pipeline.direct.duration_s = args.duration_s;
  options.pipeline.direct.fps = args.fps;
  PX_ASSIGN_OR_RETURN(options.pipeline.direct.timing.style, ParseClipStyle(args.style));
  PX_ASSIGN_OR_RETURN(options.pipeline.direct.timing.ease, ParseClipEase(args.ease));
  options.pipeline.direct.timing.hold_s = args.hold_s;
  if (!args.size.empty()) {
    PX_RETURN_IF_ERROR(ParseOutputSize(args.size, &options.pipeline.direct.output).WithContext("--size"));
  } else {
    PX_RETURN_IF_ERROR(ParseOutputAspect(args.aspect, &options.pipeline.direct.output).WithContext("--aspect"));
    options.pipeline.direct.output.height = args.height;
  }
  options.pipeline.num_threads = args.threads;
  options.pipeline.image_set_max_side_px = args.max_photo_side_px;
  options.clip.crf = args.crf;
  options.clip.preset = args.preset;
  options.clip.fps = args.fps;
  options.clip.loop_count = args.loop_count;
  options.clip.webp_quality = args.webp_quality;
  PX_ASSIGN_OR_RETURN(options.pipeline.render.quality, ParseRenderQuality(args.quality));
  PX_ASSIGN_OR_RETURN(options.pipeline.render_backend.backend, render::gl::ParseRenderBackend(args.gl));
  PX_RETURN_IF_ERROR(options.Validate());
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
    PX_ASSIGN_OR_RETURN(report, device::RunClipJob(recording, std::filesystem::absolute(source), output, options, show));
  } else {
    PX_ASSIGN_OR_RETURN(Recording recording, PhotoFolderAsRecording(source));
    PX_ASSIGN_OR_RETURN(report, device::RunClipJob(recording, std::filesystem::absolute(source), output, options, show));
  }
  progress.Finish();
  // The shot that reproduces this clip, for replaying or editing it (--shot).
  std::filesystem::path shot_path = report.clip_path;
  shot_path.replace_extension(".shot.json");
  PX_RETURN_IF_ERROR(
      WriteFileAtomically(shot_path, direct::ShotToJson(direct::ShotFromPath(report.pipeline.path)).dump(2) + "\n"));
  log->info("shot written to {}", shot_path.string());
  for (const std::string& warning : report.pipeline.warnings) log->warn("{}", warning);
  for (const StageTiming& t : report.pipeline.timings) log->info("{:<8} {:8.1f} ms", t.stage, t.ms);
  if (!report.pipeline.render_backend.empty()) {
    log->info("rendered on {} ({})", report.pipeline.render_backend, report.pipeline.render_backend_reason);
  }
  log->info("{} {} frames {}x{}, {:.1f} KiB, {:.1f} ms in all; report {}", report.format, report.frames_written,
            report.width, report.height, report.clip_bytes / 1024.0, report.total_ms, report.report_path.string());
  std::printf("%s\n", report.clip_path.c_str());
  return OkStatus();
}

}  // namespace

void AddClipCommand(CLI::App& app) {
  auto args = std::make_shared<ClipArgs>();
  CLI::App* clip = app.add_subcommand("clip", "Turn a recording into a clip (the offline pipeline)");
  clip->add_option("recording", args->recording,
                   "Recording folder (see sim/replay/FORMAT.md), a folder of hand-held photos (JPEG, PNG) taken as "
                   "an image set, a 3D camera's MPO file or a wigglegram's animated GIF or WebP")
      ->required()
      ->check(CLI::ExistingPath);
  clip->add_option("-o,--output", args->output,
                   "Clip to write (a folder for --format png); its camera path and report (JSON) go beside it")
      ->required();
  clip->add_option("--move", args->move, "Camera move: " + KnownMovesText())
      ->capture_default_str();
  clip->add_option("--effect", args->effect, "Image effect: " + KnownEffectsText())->capture_default_str();
  clip->add_option("--seed", args->seed, "Seed of the automatic choice (same seed, same clip)")->capture_default_str();
  clip->add_option("--shot", args->shot, "Authored shot (JSON, pipeline/direct/SHOT_FORMAT.md) instead of the choice")
      ->check(CLI::ExistingFile);
  clip->add_option("--subject", args->subject_px,
                   "A subject as x y w h in centre-view pixels (repeatable); replaces face detection");
  clip->add_flag("--no-faces", args->no_faces, "Do not detect faces (only --subject regions are subjects)");
  clip->add_option("--duration", args->duration_s, "Clip length in seconds")->capture_default_str();
  clip->add_option("--fps", args->fps, "Frames per second")->capture_default_str();
  clip->add_option("--style", args->style,
                   "once (the move, then --hold), loop (out and back in --duration, seamless when repeated) or "
                   "boomerang (the move, then the same frames backwards)")
      ->check(CLI::IsMember({"once", "loop", "boomerang"}))
      ->capture_default_str();
  clip->add_option("--ease", args->ease,
                   "smooth (eases in and out: no abrupt start or stop) or linear (constant speed, as in the paper)")
      ->check(CLI::IsMember({"smooth", "linear"}))
      ->capture_default_str();
  clip->add_option("--hold", args->hold_s, "once: seconds the last frame is held after the move, 0..60")
      ->capture_default_str();
  clip->add_option("--size", args->size,
                   "Output size WxH (1920x1080, 1080x1920); the move is planned in that frame, cut from the widest "
                   "field of its aspect the capture saw (the clip's JSON says if it is upsampled)");
  clip->add_option("--aspect", args->aspect, "Output aspect W:H (16:9, 9:16, 1:1, 4:5) or source; see --height")
      ->capture_default_str();
  clip->add_option("--height", args->height, "With --aspect: output height in pixels, 0 = the capture's")
      ->capture_default_str();
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
  clip->add_option("--gl", args->gl,
                   "Render back end: auto (GL on a GPU, else the faster one here, today the cpu), cpu, egl "
                   "(GPU device or Mesa surfaceless) or osmesa; a GL back end that cannot start falls back to "
                   "the cpu, and the clip's JSON says which drew it and why")
      ->check(CLI::IsMember({"auto", "cpu", "egl", "osmesa"}))
      ->capture_default_str();
  clip->add_option("--threads", args->threads, "Worker threads, 0 = all cores")->capture_default_str();
  clip->add_option("--max-photo-side", args->max_photo_side_px,
                   "Hand-held photos (an image set, e.g. from `parallax import`) are processed, and the clip made, at "
                   "this longer side at most; 0 = full size")
      ->capture_default_str();
  clip->add_flag("-q,--quiet", args->quiet, "No progress bar");
  clip->callback(RunOrFail("clip", [args] { return RunClip(*args); }));
}

}  // namespace px::cli
