#include "tools/clip_flags.h"

#include <memory>
#include <nlohmann/json.hpp>
#include <utility>

#include "device/face_cascades.h"
#include "pipeline/core/log.h"
#include "pipeline/direct/shot_file.h"
#include "pipeline/io/durable_file.h"
#include "pipeline/render/gl/render_backend.h"

namespace px::cli {

std::vector<CLI::Option*> AddClipFlags(CLI::App& command, ClipFlags& flags) {
  std::vector<CLI::Option*> options;
  options.push_back(
      command.add_option("--move", flags.move, "Camera move: " + KnownMovesText())->capture_default_str());
  options.push_back(
      command.add_option("--effect", flags.effect, "Image effect: " + KnownEffectsText())->capture_default_str());
  options.push_back(command.add_option("--seed", flags.seed, "Seed of the automatic choice (same seed, same clip)")
                        ->capture_default_str());
  options.push_back(command
                        .add_option("--shot",
                                    flags.shot,
                                    "Authored shot (JSON, pipeline/direct/SHOT_FORMAT.md) instead of the choice")
                        ->check(CLI::ExistingFile));
  options.push_back(
      command.add_option("--subject",
                         flags.subject_px,
                         "A subject as x y w h in centre-view pixels (repeatable); replaces face detection"));
  options.push_back(
      command.add_flag("--no-faces", flags.no_faces, "Do not detect faces (only --subject regions are subjects)"));
  options.push_back(
      command.add_option("--duration", flags.duration_s, "Clip length in seconds")->capture_default_str());
  options.push_back(command.add_option("--fps", flags.fps, "Frames per second")->capture_default_str());
  options.push_back(
      command
          .add_option("--style",
                      flags.style,
                      "once (the move, then --hold), loop (out and back in --duration, seamless when repeated) or "
                      "boomerang (the move, then the same frames backwards)")
          ->check(CLI::IsMember({"once", "loop", "boomerang"}))
          ->capture_default_str());
  options.push_back(
      command
          .add_option("--ease",
                      flags.ease,
                      "smooth (eases in and out: no abrupt start or stop) or linear (constant speed, as in the paper)")
          ->check(CLI::IsMember({"smooth", "linear"}))
          ->capture_default_str());
  options.push_back(
      command.add_option("--hold", flags.hold_s, "once: seconds the last frame is held after the move, 0..60")
          ->capture_default_str());
  options.push_back(command.add_option(
      "--size",
      flags.size,
      "Output size WxH (1920x1080, 1080x1920); the move is planned in that frame, cut from the widest "
      "field of its aspect the capture saw (the clip's JSON says if it is upsampled)"));
  options.push_back(
      command.add_option("--aspect", flags.aspect, "Output aspect W:H (16:9, 9:16, 1:1, 4:5) or source; see --height")
          ->capture_default_str());
  options.push_back(
      command.add_option("--height", flags.height, "With --aspect: output height in pixels, 0 = the capture's")
          ->capture_default_str());
  options.push_back(
      command
          .add_option("--format",
                      flags.format,
                      "mp4 (H.264), gif or webp (looping animations), png (a folder of frames), or auto: from the "
                      "output's extension (.mp4, .gif, .webp; a folder: png), else mp4")
          ->check(CLI::IsMember({"auto", "mp4", "gif", "webp", "png"}))
          ->capture_default_str());
  options.push_back(
      command.add_option("--crf", flags.crf, "mp4: x264 quality, 0..51, lower is better")->capture_default_str());
  options.push_back(
      command.add_option("--preset", flags.preset, "mp4: x264 preset, ultrafast..veryslow")->capture_default_str());
  options.push_back(command.add_option("--loop", flags.loop_count, "gif, webp: times the animation plays, 0 = forever")
                        ->capture_default_str());
  options.push_back(
      command.add_option("--webp-quality", flags.webp_quality, "webp: lossy quality, 0..100")->capture_default_str());
  options.push_back(
      command
          .add_option("--quality",
                      flags.quality,
                      "Render quality: preview (paper 6.1, real time) or offline (6.2: soft z over all segments, "
                      "exemplar inpainting, synthetic-aperture depth of field)")
          ->capture_default_str());
  options.push_back(
      command
          .add_option("--gl",
                      flags.gl,
                      "Render back end: auto (GL on a GPU, else the faster one here, today the cpu), cpu, egl "
                      "(GPU device or Mesa surfaceless) or osmesa; a GL back end that cannot start falls back to "
                      "the cpu, and the clip's JSON says which drew it and why")
          ->check(CLI::IsMember({"auto", "cpu", "egl", "osmesa"}))
          ->capture_default_str());
  options.push_back(
      command
          .add_option("--depth-mode",
                      flags.depth_mode,
                      "Depth options: auto (the light-field set for a dense grid of views a pixel or two apart, "
                      "e.g. a plenoptic camera's; the standard set otherwise), standard or light-field")
          ->check(CLI::IsMember({"auto", "standard", "light-field"}))
          ->capture_default_str());
  options.push_back(
      command.add_option("--threads", flags.threads, "Worker threads, 0 = all cores")->capture_default_str());
  options.push_back(
      command
          .add_option(
              "--max-photo-side",
              flags.max_photo_side_px,
              "Hand-held photos (an image set, e.g. from `parallax import`) are processed, and the clip made, at "
              "this longer side at most; 0 = full size")
          ->capture_default_str());
  return options;
}

StatusOr<device::ClipJobOptions> ClipJobOptionsFromFlags(const ClipFlags& flags, clip::ClipFormat format) {
  device::ClipJobOptions options;
  options.clip.format = format;
  options.pipeline.direct.move = flags.move;
  options.pipeline.direct.effect = flags.effect;
  options.pipeline.direct.seed = flags.seed;
  if (flags.subject_px.size() % 4 != 0) {
    return InvalidArgumentError("--subject: " + std::to_string(flags.subject_px.size()) +
                                " numbers, want x y w h for each subject");
  }
  for (size_t i = 0; i + 3 < flags.subject_px.size(); i += 4) {
    options.pipeline.direct.subject_boxes_px.emplace_back(
        flags.subject_px[i], flags.subject_px[i + 1], flags.subject_px[i + 2], flags.subject_px[i + 3]);
  }
  if (!flags.shot.empty()) {
    PX_ASSIGN_OR_RETURN(std::string text, ReadFileToString(flags.shot));
    const nlohmann::json j = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
    if (j.is_discarded()) return InvalidArgumentError("--shot " + flags.shot + ": not valid JSON");
    PX_ASSIGN_OR_RETURN(direct::Shot shot, direct::ShotFromJson(j));
    options.pipeline.shot = std::make_shared<const direct::Shot>(std::move(shot));
  }
  options.pipeline.direct.duration_s = flags.duration_s;
  options.pipeline.direct.fps = flags.fps;
  PX_ASSIGN_OR_RETURN(options.pipeline.direct.timing.style, ParseClipStyle(flags.style));
  PX_ASSIGN_OR_RETURN(options.pipeline.direct.timing.ease, ParseClipEase(flags.ease));
  options.pipeline.direct.timing.hold_s = flags.hold_s;
  if (!flags.size.empty()) {
    PX_RETURN_IF_ERROR(ParseOutputSize(flags.size, &options.pipeline.direct.output).WithContext("--size"));
  } else {
    PX_RETURN_IF_ERROR(ParseOutputAspect(flags.aspect, &options.pipeline.direct.output).WithContext("--aspect"));
    options.pipeline.direct.output.height = flags.height;
  }
  options.pipeline.num_threads = flags.threads;
  options.pipeline.image_set_max_side_px = flags.max_photo_side_px;
  options.clip.crf = flags.crf;
  options.clip.preset = flags.preset;
  options.clip.fps = flags.fps;
  options.clip.loop_count = flags.loop_count;
  options.clip.webp_quality = flags.webp_quality;
  PX_ASSIGN_OR_RETURN(options.pipeline.render.quality, ParseRenderQuality(flags.quality));
  options.pipeline.depth.mode = flags.depth_mode == "standard"      ? DepthMode::kStandard
                                : flags.depth_mode == "light-field" ? DepthMode::kLightField
                                                                    : DepthMode::kAuto;
  PX_ASSIGN_OR_RETURN(options.pipeline.render_backend.backend, render::gl::ParseRenderBackend(flags.gl));
  PX_RETURN_IF_ERROR(options.Validate());
  return options;
}

void LoadFaceDetectorUnlessOff(const ClipFlags& flags, device::ClipJobOptions& options) {
  if (flags.no_faces) return;
  StatusOr<std::shared_ptr<const direct::FaceDetector>> detector = device::LoadFaceDetector();
  if (detector.ok()) {
    options.pipeline.face_detector = *detector;
  } else {
    Logger("clip")->warn("no face detection: {}", detector.status().message());
  }
}

}  // namespace px::cli
