#include "sim/synthetic/synthetic_source.h"

#include <optional>

#include "pipeline/core/log.h"
#include "sim/synthetic/data_paths.h"
#include "sim/synthetic/scene_json.h"

namespace px {
namespace {

class SyntheticSource final : public FrameSource {
 public:
  SyntheticSource(const SyntheticSourceOptions& options, sim::Scene scene)
      : options_(options), scene_(std::move(scene)) {
    if (options_.clock == nullptr)
      clock_ = &steady_clock_;
    else
      clock_ = options_.clock;
    exposure_gains_ = sim::DrawExposureGains(options_.camera, options_.seed);
  }

  std::string_view Name() const override { return "sim"; }

  SourceDescription Describe() const override {
    SourceDescription description;
    description.model = "sim:" + options_.camera.name;
    description.kind = FrameSetKind::kLatticeFrame;
    description.rig = options_.camera.Calibration();
    return description;
  }

  StatusOr<ConfigureResult> Configure(const SourceConfig& wanted, SourceConfig* granted) override {
    const LatticeLayout layout = options_.camera.Layout();
    SourceConfig grant;
    grant.width = layout.sensor_width;
    grant.height = layout.sensor_height;
    grant.shots = 1;
    grant.pixel_format = wanted.pixel_format;
    if (!PackedImageBytes(wanted.pixel_format, grant.width, grant.height).ok()) {
      grant.pixel_format = options_.camera.pixel_format;  // Validate() made sure this one fits
    }
    // 0 asks for the native size, so granting it is not an adjustment.
    const bool size_ok =
        (wanted.width == 0 || wanted.width == grant.width) && (wanted.height == 0 || wanted.height == grant.height);
    const bool adjusted = !size_ok || wanted.shots != 1 || grant.pixel_format != wanted.pixel_format;
    *granted = grant;
    granted_ = grant;
    return adjusted ? ConfigureResult::kAdjusted : ConfigureResult::kValid;
  }

  StatusOr<FrameSet> Next(std::chrono::milliseconds /*timeout*/) override {
    if (!granted_) {
      return FailedPreconditionError("sim source '" + options_.camera.name + "': Next() before Configure()" +
                                     (stopped_ ? " (stopped)" : ""));
    }
    if (!views_) {
      PX_ASSIGN_OR_RETURN(std::vector<sim::ViewTruth> views, sim::RenderLatticeViews(scene_, options_.camera));
      views_ = std::move(views);
    }
    const uint64_t sequence = next_sequence_++;
    sim::GroundTruth truth;
    truth.scene_name = scene_.name;
    truth.rig = options_.camera.TrueCalibration();
    truth.views = *views_;
    truth.exposure_gains = exposure_gains_;
    truth.noise_seed = sim::CaptureNoiseSeed(options_.seed, sequence);
    const cv::Mat bgr = sim::ComposeSensorBgr(options_.camera, truth.views, truth.exposure_gains, truth.noise_seed);

    Frame frame;
    PX_ASSIGN_OR_RETURN(frame.image, FromBgr(bgr, granted_->pixel_format));
    frame.sequence = sequence;
    frame.timestamp_ns = clock_->NowNs();
    FrameSet frames;
    frames.kind = FrameSetKind::kLatticeFrame;
    frames.capture_id = next_capture_id_++;
    frames.frames.push_back(std::move(frame));
    last_truth_ = std::move(truth);
    Logger("sim")->debug("sim capture {} (sequence {}) {}", frames.capture_id, sequence, DescribeConfig(*granted_));
    return frames;
  }

  void Stop() override {
    if (granted_) stopped_ = true;
    granted_.reset();
  }

  const std::optional<sim::GroundTruth>& last_truth() const { return last_truth_; }

 private:
  SyntheticSourceOptions options_;
  sim::Scene scene_;
  SteadyClock steady_clock_;
  Clock* clock_ = nullptr;
  std::vector<double> exposure_gains_;  // per lens, fixed for the camera's life
  std::optional<SourceConfig> granted_;
  bool stopped_ = false;
  std::optional<std::vector<sim::ViewTruth>> views_;  // the clean render, made once
  std::optional<sim::GroundTruth> last_truth_;
  uint64_t next_sequence_ = 0;
  uint64_t next_capture_id_ = 1;
};

}  // namespace

StatusOr<std::unique_ptr<FrameSource>> MakeSyntheticSource(const SyntheticSourceOptions& options) {
  PX_RETURN_IF_ERROR(options.camera.Validate());
  const std::filesystem::path scene_file =
      options.scene_file.empty() ? sim::ScenesDir() / "still_life.json" : options.scene_file;
  PX_ASSIGN_OR_RETURN(sim::Scene scene, sim::LoadScene(scene_file));
  return std::unique_ptr<FrameSource>(new SyntheticSource(options, std::move(scene)));
}

StatusOr<sim::GroundTruth> LastGroundTruth(const FrameSource& source) {
  const auto* synthetic = dynamic_cast<const SyntheticSource*>(&source);
  if (synthetic == nullptr) {
    return InvalidArgumentError("source '" + std::string(source.Name()) + "' is not a synthetic source");
  }
  if (!synthetic->last_truth()) return FailedPreconditionError("sim source: no capture yet");
  // Deep copies: the source keeps sharing its cached render with later captures.
  sim::GroundTruth truth = *synthetic->last_truth();
  for (sim::ViewTruth& view : truth.views) {
    view.bgr = view.bgr.clone();
    view.depth_m = view.depth_m.clone();
  }
  return truth;
}

}  // namespace px
