#include "tools/bench_command.h"

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "capture/import_images.h"
#include "pipeline/clip/mp4_writer.h"
#include "pipeline/core/log.h"
#include "pipeline/core/stage_clock.h"
#include "pipeline/direct/output_frame.h"
#include "pipeline/render/gl/render_backend.h"
#include "pipeline/run/pipeline.h"
#include "sim/synthetic/handheld_photos.h"
#include "sim/synthetic/synthetic_source.h"
#include "tools/bench_presets.h"
#include "tools/consistent_blend_flags.h"
#include "tools/depth_option_override.h"
#include "tools/machine_info.h"
#include "tools/progress_bar.h"
#include "tools/run_or_fail.h"
#include "tools/scene_path.h"

namespace px::cli {
namespace {

struct BenchArgs {
  std::string preset = "standard";
  std::string scene = "still_life";
  std::string camera;  // "" = the preset's
  double duration_s = 5.0;
  double fps = 30.0;
  std::string size;         // "WxH"; "" = the preset's
  std::string output;       // where the clip goes; default: a temporary file removed afterwards
  std::string gl = "auto";  // render back end
  bool json = false;
  std::vector<std::string> depth_overrides;  // "matching.sgm_paths=0"
  ConsistentBlendOptions consistent_blend;
};

// Encodes frames as the pipeline renders them and times only the encoding. The writer opens on
// the first frame: the clip has the size the pipeline chose.
class TimedMp4Sink final : public FrameSink {
 public:
  TimedMp4Sink(std::filesystem::path path, double fps) : path_(std::move(path)) { options_.fps = fps; }
  Status Consume(int /*index*/, const cv::Mat& bgr) override {
    const auto start = StageClock::now();
    if (!writer_) {
      PX_ASSIGN_OR_RETURN(writer_, clip::Mp4Writer::Open(path_, bgr.cols, bgr.rows, options_));
    }
    Status status = writer_->Write(bgr);
    encode_ms_ += MsSince(start);
    return status;
  }
  Status Finish() {
    if (!writer_) return InternalError("the pipeline rendered no frames");
    const auto start = StageClock::now();
    Status status = writer_->Finish();
    encode_ms_ += MsSince(start);
    return status;
  }
  double encode_ms() const { return encode_ms_; }

 private:
  std::filesystem::path path_;
  clip::Mp4Options options_;
  std::unique_ptr<clip::Mp4Writer> writer_;
  double encode_ms_ = 0;
};

// What the camera delivered, ready for the pipeline, and what getting it cost.
struct BenchCapture {
  FrameSet frames;
  RigCalibration rig;  // empty for a hand-held set (posed by structure from motion)
  std::string camera;
  int view_width = 0;
  int view_height = 0;
  double capture_ms = 0;  // the simulator's render: not part of capture to clip
  double import_ms = 0;   // hand-held: reading and decoding the photos, as `parallax clip FOLDER` does
};

StatusOr<BenchCapture> CaptureLattice(const SimCameraSpec& camera, const std::filesystem::path& scene_file) {
  SyntheticSourceOptions sim;
  sim.camera = camera;
  sim.scene_file = scene_file;
  PX_ASSIGN_OR_RETURN(std::unique_ptr<FrameSource> source, MakeSyntheticSource(sim));
  SourceConfig granted;
  PX_ASSIGN_OR_RETURN(ConfigureResult configured, source->Configure(SourceConfig{sim.camera.pixel_format}, &granted));
  (void)configured;
  BenchCapture capture;
  const auto start = StageClock::now();
  PX_ASSIGN_OR_RETURN(capture.frames, source->Next(std::chrono::milliseconds(600000)));
  capture.capture_ms = MsSince(start);
  capture.rig = *source->Describe().rig;
  capture.camera = camera.name;
  capture.view_width = camera.tile_width;
  capture.view_height = camera.tile_height;
  return capture;
}

// Removes the simulated photos however the bench ends.
class RemoveFolder {
 public:
  explicit RemoveFolder(std::filesystem::path path) : path_(std::move(path)) {}
  ~RemoveFolder() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  RemoveFolder(const RemoveFolder&) = delete;
  RemoveFolder& operator=(const RemoveFolder&) = delete;

 private:
  std::filesystem::path path_;
};

StatusOr<BenchCapture> CaptureHandHeld(const sim::HandHeldPhotoOptions& photos,
                                       const std::filesystem::path& scene_file) {
  const std::filesystem::path folder =
      std::filesystem::temp_directory_path() / ("parallax_bench_photos_" + std::to_string(::getpid()));
  RemoveFolder remove(folder);
  BenchCapture capture;
  auto start = StageClock::now();
  PX_ASSIGN_OR_RETURN(std::vector<std::filesystem::path> files, sim::WriteHandHeldPhotos(scene_file, photos, folder));
  capture.capture_ms = MsSince(start);
  start = StageClock::now();
  std::vector<std::string> warnings;
  PX_ASSIGN_OR_RETURN(Recording recording, RecordingFromImages(files, &warnings));
  capture.import_ms = MsSince(start);
  capture.frames = std::move(recording.frames);
  capture.camera = "sim hand-held photos";
  capture.view_width = photos.width;
  capture.view_height = photos.height;
  return capture;
}

Status RunBench(const BenchArgs& args) {
  PX_ASSIGN_OR_RETURN(BenchPreset preset, FindBenchPreset(args.preset));
  if (!args.camera.empty()) {
    if (preset.handheld)
      return InvalidArgumentError("--camera does not apply to " + preset.name + " (hand-held photos)");
    if (args.camera != "pop9" && args.camera != "integral5x4") {
      return InvalidArgumentError("--camera '" + args.camera + "' is not pop9 or integral5x4");
    }
    preset.camera = args.camera == "integral5x4" ? SimCameraSpec::Integral5x4() : SimCameraSpec::Pop9();
  }
  const std::string size = args.size.empty() ? preset.size : args.size;
  PipelineOptions options;
  options.direct.duration_s = args.duration_s;
  options.direct.fps = args.fps;
  if (!size.empty()) {
    PX_RETURN_IF_ERROR(ParseOutputSize(size, &options.direct.output).WithContext("--size"));
  }
  options.render.consistent_blend = args.consistent_blend;
  PX_ASSIGN_OR_RETURN(options.render_backend.backend, render::gl::ParseRenderBackend(args.gl));
  for (const std::string& text : args.depth_overrides) {
    PX_RETURN_IF_ERROR(ApplyDepthOptionOverride(text, &options.depth));
  }
  PX_RETURN_IF_ERROR(options.depth.Validate());
  PX_ASSIGN_OR_RETURN(const std::filesystem::path scene_file, ResolveScenePath(args.scene));

  Logger("bench")->info("preset {}: {}; simulating the capture", preset.name, preset.description);
  const auto total_start = StageClock::now();
  PX_ASSIGN_OR_RETURN(
      BenchCapture capture,
      preset.handheld ? CaptureHandHeld(preset.photos, scene_file) : CaptureLattice(preset.camera, scene_file));

  std::filesystem::path clip_path = args.output.empty() ? std::filesystem::temp_directory_path() / "parallax_bench.mp4"
                                                        : std::filesystem::path(args.output);
  TimedMp4Sink sink(clip_path, args.fps);
  ProgressBar progress(args.json);
  PX_ASSIGN_OR_RETURN(
      PipelineReport report,
      RunPipeline(capture.frames, capture.rig, options, &sink, [&](const std::string& stage, double fraction) {
        progress.Update(stage, fraction);
        return true;
      }));
  PX_RETURN_IF_ERROR(sink.Finish());
  progress.Finish();
  const double total_ms = MsSince(total_start);
  if (args.output.empty()) std::filesystem::remove(clip_path);

  // The pipeline times rendering apart from its sink; the sink's own clock also covers the
  // encoder's final flush (Finish), so its figure replaces the pipeline's "encode".
  nlohmann::json stages = nlohmann::json::array();
  stages.push_back({{"stage", "capture (sim render)"}, {"ms", capture.capture_ms}});
  if (preset.handheld) stages.push_back({{"stage", "import"}, {"ms", capture.import_ms}});
  double render_ms = 0;
  for (const StageTiming& t : report.timings) {
    if (t.stage == "encode") continue;
    if (t.stage == "render") render_ms = t.ms;
    stages.push_back({{"stage", t.stage}, {"ms", t.ms}});
  }
  stages.push_back({{"stage", "encode"}, {"ms", sink.encode_ms()}});
  const MachineInfo machine = ReadMachineInfo();
  const int width = report.path.width, height = report.path.height;
  nlohmann::json result{{"preset", preset.name},
                        {"shot",
                         {{"camera", capture.camera},
                          {"views", report.num_views},
                          {"view_width", capture.view_width},
                          {"view_height", capture.view_height},
                          {"width", width},
                          {"height", height},
                          {"scene", args.scene},
                          {"frames", report.frames_rendered},
                          {"fps", args.fps},
                          {"duration_s", args.duration_s},
                          {"depth_options", args.depth_overrides}}},
                        {"stages", stages},
                        {"total_ms", total_ms},
                        {"pipeline_ms", total_ms - capture.capture_ms},
                        {"ms_per_frame_render", report.frames_rendered > 0 ? render_ms / report.frames_rendered : 0.0},
                        {"mean_hole_ratio", report.mean_hole_ratio},
                        {"render_backend", report.render_backend},
                        {"render_backend_reason", report.render_backend_reason},
                        {"peak_rss_mib", PeakRssMiB()},
                        {"machine",
                         {{"cpu", machine.cpu_model},
                          {"cores", machine.cores},
                          {"memory_gib", machine.memory_gib},
                          {"commit", machine.commit}}}};
  if (args.json) {
    std::printf("%s\n", result.dump(2).c_str());
    return OkStatus();
  }
  std::printf("preset %s: %s, %d views of %dx%d, %d frames of %dx%d (%.1f s at %.0f fps), scene %s\n",
              preset.name.c_str(),
              capture.camera.c_str(),
              report.num_views,
              capture.view_width,
              capture.view_height,
              report.frames_rendered,
              width,
              height,
              args.duration_s,
              args.fps,
              args.scene.c_str());
  std::string overrides;
  for (const std::string& text : args.depth_overrides) overrides += " " + text;
  if (!overrides.empty()) std::printf("depth options:%s\n", overrides.c_str());
  std::printf("machine: %s, %d cores, %.1f GiB, commit %s\n",
              machine.cpu_model.c_str(),
              machine.cores,
              machine.memory_gib,
              machine.commit.c_str());
  for (const auto& stage : stages) {
    std::printf("  %-22s %10.1f ms\n", stage["stage"].get<std::string>().c_str(), stage["ms"].get<double>());
  }
  std::printf("  %-22s %10.1f ms  (capture to clip, without the simulated capture: %.1f ms)\n",
              "total",
              total_ms,
              total_ms - capture.capture_ms);
  std::printf("  %-22s %10.2f ms\n", "render per frame", result["ms_per_frame_render"].get<double>());
  std::printf("  %-22s %10.3f\n", "mean hole ratio", report.mean_hole_ratio);
  std::printf("  %-22s %s (%s)\n", "rendered on", report.render_backend.c_str(), report.render_backend_reason.c_str());
  std::printf("  %-22s %10.1f MiB\n", "peak RSS", PeakRssMiB());
  return OkStatus();
}

}  // namespace

void AddBenchCommand(CLI::App& app) {
  auto args = std::make_shared<BenchArgs>();
  CLI::App* bench = app.add_subcommand(
      "bench",
      "Time a shot end to end, every stage and the peak memory: the standard shot (simulated Pop9, 9 views of "
      "640x480, 5 s at 30 fps) or a preset at a real camera's resolution");
  std::string presets;
  for (const BenchPreset& preset : BenchPresets()) presets += "; " + preset.name + ": " + preset.description;
  bench->add_option("--preset", args->preset, "The shot" + presets)->capture_default_str();
  bench->add_option("--scene", args->scene, "Scene name in sim/scenes or a scene JSON path")->capture_default_str();
  bench->add_option(
      "--camera", args->camera, "A lattice preset's camera instead: pop9 or integral5x4 (their own tiles)");
  bench->add_option("--duration", args->duration_s, "Clip length in seconds")->capture_default_str();
  bench->add_option("--fps", args->fps, "Frames per second")->capture_default_str();
  bench->add_option(
      "--size", args->size, "Output size WxH (1080x1920), default the preset's (standard: the views' size)");
  bench->add_option("-o,--output", args->output, "Keep the clip at this path (default: discard it)");
  bench->add_option("--option",
                    args->depth_overrides,
                    "Override one depth option, name=value as in pipeline/depth/depth_options.h (repeatable), "
                    "e.g. --option matching.sgm_paths=0");
  bench->add_option("--gl", args->gl, "Render back end: auto, cpu, egl or osmesa (as parallax clip --gl)")
      ->check(CLI::IsMember({"auto", "cpu", "egl", "osmesa"}))
      ->capture_default_str();
  AddConsistentBlendFlags(*bench, &args->consistent_blend);
  bench->add_flag("--json", args->json, "Print the figures as JSON (machine-readable)");
  bench->callback(RunOrFail("bench", [args] { return RunBench(*args); }));
}

}  // namespace px::cli
