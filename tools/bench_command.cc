#include "tools/bench_command.h"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "pipeline/clip/mp4_writer.h"
#include "pipeline/core/log.h"
#include "pipeline/direct/output_frame.h"
#include "pipeline/run/pipeline.h"
#include "sim/synthetic/synthetic_source.h"
#include "tools/consistent_blend_flags.h"
#include "tools/depth_option_override.h"
#include "tools/machine_info.h"
#include "tools/progress_bar.h"
#include "tools/run_or_fail.h"
#include "tools/scene_path.h"

namespace px::cli {
namespace {

using Clock = std::chrono::steady_clock;

double MsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

struct BenchArgs {
  std::string scene = "still_life";
  std::string camera = "pop9";
  double duration_s = 5.0;
  double fps = 30.0;
  std::string size;    // "WxH"; "" = the views' size
  std::string output;  // where the clip goes; default: a temporary file removed afterwards
  bool json = false;
  std::vector<std::string> depth_overrides;  // "matching.sgm_paths=0"
  ConsistentBlendOptions consistent_blend;
};

// Encodes frames as the pipeline renders them and times only the encoding.
class TimedMp4Sink final : public FrameSink {
 public:
  explicit TimedMp4Sink(std::unique_ptr<clip::Mp4Writer> writer) : writer_(std::move(writer)) {}
  Status Consume(int /*index*/, const cv::Mat& bgr) override {
    const auto start = Clock::now();
    Status status = writer_->Write(bgr);
    encode_ms_ += MsSince(start);
    return status;
  }
  Status Finish() {
    const auto start = Clock::now();
    Status status = writer_->Finish();
    encode_ms_ += MsSince(start);
    return status;
  }
  double encode_ms() const { return encode_ms_; }

 private:
  std::unique_ptr<clip::Mp4Writer> writer_;
  double encode_ms_ = 0;
};

Status RunBench(const BenchArgs& args) {
  PipelineOptions options;
  options.direct.duration_s = args.duration_s;
  options.direct.fps = args.fps;
  if (!args.size.empty()) {
    PX_RETURN_IF_ERROR(ParseOutputSize(args.size, &options.direct.output).WithContext("--size"));
  }
  options.render.consistent_blend = args.consistent_blend;
  for (const std::string& text : args.depth_overrides) {
    PX_RETURN_IF_ERROR(ApplyDepthOptionOverride(text, &options.depth));
  }
  PX_RETURN_IF_ERROR(options.depth.Validate());
  SyntheticSourceOptions sim;
  sim.camera = args.camera == "integral5x4" ? SimCameraSpec::Integral5x4() : SimCameraSpec::Pop9();
  if (args.camera != "pop9" && args.camera != "integral5x4") {
    return InvalidArgumentError("--camera '" + args.camera + "' is not pop9 or integral5x4");
  }
  PX_ASSIGN_OR_RETURN(sim.scene_file, ResolveScenePath(args.scene));
  PX_ASSIGN_OR_RETURN(std::unique_ptr<FrameSource> source, MakeSyntheticSource(sim));
  SourceConfig granted;
  PX_ASSIGN_OR_RETURN(ConfigureResult configured, source->Configure(SourceConfig{sim.camera.pixel_format}, &granted));
  (void)configured;

  const auto total_start = Clock::now();
  auto start = Clock::now();
  PX_ASSIGN_OR_RETURN(FrameSet capture, source->Next(std::chrono::milliseconds(600000)));
  const double capture_ms = MsSince(start);
  const RigCalibration rig = *source->Describe().rig;

  const int tile_w = rig.lenses[0].camera.width, tile_h = rig.lenses[0].camera.height;
  const OutputSize out = ResolveOutputSize(options.direct.output, tile_w, tile_h);
  std::filesystem::path clip_path = args.output.empty() ? std::filesystem::temp_directory_path() / "parallax_bench.mp4"
                                                        : std::filesystem::path(args.output);
  clip::Mp4Options mp4;
  mp4.fps = args.fps;
  PX_ASSIGN_OR_RETURN(auto writer, clip::Mp4Writer::Open(clip_path, out.width, out.height, mp4));
  TimedMp4Sink sink(std::move(writer));
  ProgressBar progress(args.json);
  PX_ASSIGN_OR_RETURN(PipelineReport report,
                      RunPipeline(capture, rig, options, &sink, [&](const std::string& stage, double fraction) {
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
  stages.push_back({{"stage", "capture (sim render)"}, {"ms", capture_ms}});
  double render_ms = 0;
  for (const StageTiming& t : report.timings) {
    if (t.stage == "encode") continue;
    if (t.stage == "render") render_ms = t.ms;
    stages.push_back({{"stage", t.stage}, {"ms", t.ms}});
  }
  stages.push_back({{"stage", "encode"}, {"ms", sink.encode_ms()}});
  const MachineInfo machine = ReadMachineInfo();
  nlohmann::json result{{"shot",
                         {{"camera", sim.camera.name},
                          {"views", report.num_views},
                          {"view_width", tile_w},
                          {"view_height", tile_h},
                          {"width", out.width},
                          {"height", out.height},
                          {"scene", args.scene},
                          {"frames", report.frames_rendered},
                          {"fps", args.fps},
                          {"duration_s", args.duration_s},
                          {"depth_options", args.depth_overrides}}},
                        {"stages", stages},
                        {"total_ms", total_ms},
                        {"pipeline_ms", total_ms - capture_ms},
                        {"ms_per_frame_render", report.frames_rendered > 0 ? render_ms / report.frames_rendered : 0.0},
                        {"mean_hole_ratio", report.mean_hole_ratio},
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
  std::printf("standard shot: %s, %d views of %dx%d, %d frames of %dx%d (%.1f s at %.0f fps), scene %s\n",
              sim.camera.name.c_str(),
              report.num_views,
              tile_w,
              tile_h,
              report.frames_rendered,
              out.width,
              out.height,
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
              total_ms - capture_ms);
  std::printf("  %-22s %10.2f ms\n", "render per frame", result["ms_per_frame_render"].get<double>());
  std::printf("  %-22s %10.3f\n", "mean hole ratio", report.mean_hole_ratio);
  std::printf("  %-22s %10.1f MiB\n", "peak RSS", PeakRssMiB());
  return OkStatus();
}

}  // namespace

void AddBenchCommand(CLI::App& app) {
  auto args = std::make_shared<BenchArgs>();
  CLI::App* bench = app.add_subcommand(
      "bench", "Time the standard shot end to end (simulated Pop9, 9 views of 640x480, 5 s at 30 fps)");
  bench->add_option("--scene", args->scene, "Scene name in sim/scenes or a scene JSON path")->capture_default_str();
  bench->add_option("--camera", args->camera, "Camera preset: pop9 or integral5x4")->capture_default_str();
  bench->add_option("--duration", args->duration_s, "Clip length in seconds")->capture_default_str();
  bench->add_option("--fps", args->fps, "Frames per second")->capture_default_str();
  bench->add_option("--size", args->size, "Output size WxH (1080x1920), default the views' size");
  bench->add_option("-o,--output", args->output, "Keep the clip at this path (default: discard it)");
  bench->add_option("--option",
                    args->depth_overrides,
                    "Override one depth option, name=value as in pipeline/depth/depth_options.h (repeatable), "
                    "e.g. --option matching.sgm_paths=0");
  AddConsistentBlendFlags(*bench, &args->consistent_blend);
  bench->add_flag("--json", args->json, "Print the figures as JSON (machine-readable)");
  bench->callback(RunOrFail("bench", [args] { return RunBench(*args); }));
}

}  // namespace px::cli
