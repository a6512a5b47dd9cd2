#include "tests/drivers/sim_lattice_frame.h"

#include <chrono>
#include <mutex>

#include "pipeline/core/rig_calibration_json.h"
#include "pipeline/io/durable_file.h"
#include "sim/synthetic/data_paths.h"
#include "sim/synthetic/synthetic_source.h"

namespace px::testing {

SimCameraSpec SmallPop9Spec() {
  SimCameraSpec spec = SimCameraSpec::Pop9();
  spec.name = "sim-pop9-160x120";
  spec.tile_width = 160;
  spec.tile_height = 120;
  spec.focal_px = 140;
  spec.gap_px = 6;
  spec.supersampling = 1;
  spec.pixel_format = PixelFormat::kBgr888;
  return spec;
}

StatusOr<cv::Mat> SmallPop9FrameBgr() {
  static std::mutex mutex;
  static cv::Mat frame;
  std::lock_guard<std::mutex> lock(mutex);
  if (frame.empty()) {
    SyntheticSourceOptions options;
    options.camera = SmallPop9Spec();
    options.scene_file = sim::ScenesDir() / "still_life.json";
    PX_ASSIGN_OR_RETURN(auto source, MakeSyntheticSource(options));
    SourceConfig granted;
    PX_ASSIGN_OR_RETURN(ConfigureResult configured, source->Configure(SourceConfig{PixelFormat::kBgr888}, &granted));
    (void)configured;
    PX_ASSIGN_OR_RETURN(FrameSet frames, source->Next(std::chrono::seconds(60)));
    PX_ASSIGN_OR_RETURN(cv::Mat bgr, ToBgr(frames.frames.at(0).image));
    frame = bgr;
  }
  return frame.clone();
}

Status WriteSmallPop9Calibration(const std::filesystem::path& path) {
  return WriteFileAtomically(path, RigCalibrationToJsonText(SmallPop9Spec().Calibration()));
}

}  // namespace px::testing
