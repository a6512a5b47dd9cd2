#include "device/daemon_factory.h"

#include <cstdio>

#include "device/control/peer_access.h"
#include "device/face_cascades.h"
#include "device/source_registry.h"
#include "device/trigger/input_trigger.h"
#include "device/trigger/key_codes.h"
#include "device/worker/worker_runner.h"
#include "pipeline/core/json_fields.h"
#include "pipeline/core/log.h"
#include "pipeline/direct/direct_options.h"
#include "pipeline/direct/shot_file.h"
#include "pipeline/render/gl/render_backend.h"

namespace px::device {

StatusOr<ClipJobOptions> ClipJobOptionsFromConfig(const DaemonConfig& config) {
  if (!IsKnownMove(config.clip.move)) {
    return InvalidArgumentError("clip.move: '" + config.clip.move + "' is not a known camera move");
  }
  ClipJobOptions options;
  options.pipeline.direct.move = config.clip.move;
  options.pipeline.direct.effect = config.clip.effect;
  options.pipeline.direct.duration_s = config.clip.duration_s;
  options.pipeline.direct.fps = config.clip.fps;
  // DaemonConfig::Validate checked the names.
  options.pipeline.direct.timing.style = ParseClipStyle(config.clip.style).value();
  options.pipeline.direct.timing.ease = ParseClipEase(config.clip.ease).value();
  options.pipeline.direct.timing.hold_s = config.clip.hold_s;
  PX_ASSIGN_OR_RETURN(options.pipeline.direct.output, ClipOutputFrame(config.clip));
  options.pipeline.num_threads = config.clip.num_threads;
  options.pipeline.image_set_max_side_px = config.clip.max_photo_side_px;
  // DaemonConfig::Validate checked the name.
  options.pipeline.render_backend.backend = render::gl::ParseRenderBackend(config.render.backend).value();
  options.clip.format = clip::ParseClipFormat(config.clip.format).value();  // DaemonConfig::Validate checked it
  options.clip.fps = config.clip.fps;
  options.clip.crf = config.clip.crf;
  options.clip.preset = config.clip.preset;
  options.clip.loop_count = config.clip.loop_count;
  options.clip.webp_quality = config.clip.webp_quality;
  if (!config.clip.face_cascades.empty()) {
    StatusOr<std::shared_ptr<const direct::FaceDetector>> detector = LoadFaceDetector(config.clip.face_cascades);
    if (detector.ok()) {
      options.pipeline.face_detector = *detector;
    } else {
      Logger("device")->warn("clip.face_cascades: {}; clips are directed without face detection",
                             detector.status().message());
    }
  }
  if (Status valid = options.Validate(); !valid.ok()) return valid.WithContext("clip");
  return options;
}

DaemonOptions DaemonOptionsFromConfig(const DaemonConfig& config, const DaemonRunFlags& flags) {
  DaemonOptions options;
  options.storage = config.storage;
  options.control_socket = config.control_socket;
  options.trigger_fd = flags.stdin_trigger ? 0 : -1;
  options.exit_when_idle = flags.exit_when_idle;
  options.capture_timeout = std::chrono::milliseconds(config.source.timeout_ms);
  options.created_by = "parallaxd " PX_VERSION_STRING;
  options.loop_inputs = flags.loop_inputs;
  options.max_worker_crashes = config.worker.max_crashes;
  if (!config.trigger.input_device.empty()) {
    InputTriggerOptions trigger;
    trigger.device = config.trigger.input_device;
    trigger.key_code = ParseKeyCode(config.trigger.key).value();  // DaemonConfig::Validate checked it
    trigger.debounce = std::chrono::milliseconds(config.trigger.debounce_ms);
    trigger.retry = std::chrono::milliseconds(config.trigger.retry_ms);
    options.loop_inputs.push_back(std::make_shared<InputTrigger>(trigger));
  }
  return options;
}

JobRunner MakeClipJobRunner(const ClipJobOptions& options) {
  return [options](const JobContext& context) -> StatusOr<JobOutcome> {
    ClipJobOptions job_options = options;
    PX_RETURN_IF_ERROR(ApplyPressSettings(context.settings, &job_options));  // set_settings, set_move
    if (!context.shot.empty()) {  // set_shot (validated when it was set; checked again here)
      PX_ASSIGN_OR_RETURN(nlohmann::json j, json::Parse(context.shot, "shot"));
      PX_ASSIGN_OR_RETURN(direct::Shot shot, direct::ShotFromJson(j));
      job_options.pipeline.shot = std::make_shared<const direct::Shot>(std::move(shot));
    }
    // The daemon names clips/<id>.mp4; the configured format decides the real name.
    const std::filesystem::path clip_path = ClipPathForFormat(context.clip_path, job_options.clip.format);
    PX_ASSIGN_OR_RETURN(ClipJobReport report,
                        RunClipJob(context.capture_dir, clip_path, job_options, context.progress));
    for (const std::string& warning : report.pipeline.warnings) {
      Logger("device")->warn("job {}: {}", context.job_id, warning);
    }
    char note[160];
    std::snprintf(note,
                  sizeof(note),
                  "%d frames %dx%d, %d views, %.2f MB%s",
                  report.frames_written,
                  report.width,
                  report.height,
                  report.pipeline.num_views,
                  static_cast<double>(report.clip_bytes) / 1e6,
                  report.pipeline.warnings.empty() ? "" : ", with warnings");
    return JobOutcome{note, report.clip_path};
  };
}

uint64_t WorkerMemoryLimit(const DaemonConfig& config) {
  return config.worker.memory_limit_mb > 0 ? static_cast<uint64_t>(config.worker.memory_limit_mb) << 20
                                           : DefaultWorkerMemoryLimit();
}

std::filesystem::path WorkerBinary(const DaemonRunFlags& flags) {
  return flags.worker_binary.empty() ? std::filesystem::path("/proc/self/exe") : flags.worker_binary;
}

StatusOr<std::unique_ptr<Daemon>> BuildDaemon(const DaemonConfig& config, const DaemonRunFlags& flags) {
  PX_RETURN_IF_ERROR(config.Validate());
  // Checked here, so a bad clip setting stops the daemon at start rather than failing each job.
  PX_RETURN_IF_ERROR(ClipJobOptionsFromConfig(config).status());
  PX_ASSIGN_OR_RETURN(OpenedSource opened, OpenSource(config.source));
  DaemonOptions options = DaemonOptionsFromConfig(config, flags);
  options.wanted_source = opened.wanted;
  if (!config.control_group.empty()) {
    PX_ASSIGN_OR_RETURN(options.control_group, ResolveGroup(config.control_group));
  }
  if (!config.storage_group.empty()) {
    PX_ASSIGN_OR_RETURN(options.storage.group, ResolveGroup(config.storage_group, "storage.group"));
  }
  WorkerRunnerOptions worker;
  worker.binary = WorkerBinary(flags);
  worker.config = DaemonConfigToJson(config);
  worker.memory_limit_bytes = WorkerMemoryLimit(config);
  worker.timeout = std::chrono::seconds(config.worker.timeout_s);
  std::error_code ec;
  const std::filesystem::path shown = std::filesystem::read_symlink(worker.binary, ec);
  Logger("device")->info("jobs run in worker processes ({}), killed above {} MB or after {} s",
                         (ec ? worker.binary : shown).string(),
                         worker.memory_limit_bytes >> 20,
                         config.worker.timeout_s);
  return std::make_unique<Daemon>(std::move(options), std::move(opened.source), MakeWorkerJobRunner(std::move(worker)));
}

}  // namespace px::device
