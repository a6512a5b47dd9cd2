// The conformance suite over the V4L2 driver against an emulated camera (umockdev) that serves
// the simulated Pop9 lattice frame, with and without a rig calibration, in a raw format (the
// driver converts BGR3 to RGB888) and in MJPG (decoded).
#include <filesystem>
#include <memory>
#include <string>

#include "drivers/v4l2/v4l2_source.h"
#include "tests/conformance/frame_source_conformance.h"
#include "tests/drivers/emulated_v4l2_device.h"
#include "tests/drivers/sim_lattice_frame.h"

namespace px::conformance {
namespace {

// The driver together with the emulated camera it talks to, which must outlive it.
class EmulatedV4l2Source final : public FrameSource {
 public:
  EmulatedV4l2Source(std::unique_ptr<testing::EmulatedV4l2Testbed> testbed, std::unique_ptr<V4l2Source> source)
      : testbed_(std::move(testbed)), source_(std::move(source)) {}
  ~EmulatedV4l2Source() override { source_.reset(); }

  std::string_view Name() const override { return source_->Name(); }
  SourceDescription Describe() const override { return source_->Describe(); }
  StatusOr<ConfigureResult> Configure(const SourceConfig& wanted, SourceConfig* granted) override {
    return source_->Configure(wanted, granted);
  }
  StatusOr<FrameSet> Next(std::chrono::milliseconds timeout) override { return source_->Next(timeout); }
  void Stop() override { source_->Stop(); }

 private:
  std::unique_ptr<testing::EmulatedV4l2Testbed> testbed_;
  std::unique_ptr<V4l2Source> source_;
};

StatusOr<std::unique_ptr<FrameSource>> MakeEmulated(const std::filesystem::path& dir,
                                                    std::vector<uint32_t> fourccs,
                                                    bool with_rig) {
  PX_ASSIGN_OR_RETURN(auto testbed, testing::EmulatedV4l2Testbed::Create());  // UNAVAILABLE skips
  PX_ASSIGN_OR_RETURN(cv::Mat frame, testing::SmallPop9FrameBgr());
  testing::EmulatedCameraOptions camera;
  camera.fourccs = std::move(fourccs);
  PX_ASSIGN_OR_RETURN(testing::EmulatedV4l2Camera * emulated, testbed->AddCamera(camera, frame));
  V4l2SourceOptions options;
  options.device = emulated->DevicePath();
  if (with_rig) {
    options.rig_calibration = dir / "rig.json";
    PX_RETURN_IF_ERROR(testing::WriteSmallPop9Calibration(options.rig_calibration));
  }
  PX_ASSIGN_OR_RETURN(auto source, OpenV4l2Source(options));
  return std::unique_ptr<FrameSource>(new EmulatedV4l2Source(std::move(testbed), std::move(source)));
}

std::vector<SourceCase> AllSources() {
  return {
      {"v4l2_bgr24_rig", [](const auto& dir, Clock*) { return MakeEmulated(dir, {V4L2_PIX_FMT_BGR24}, true); }},
      {"v4l2_yuyv_nv12",
       [](const auto& dir, Clock*) {
         return MakeEmulated(dir, {V4L2_PIX_FMT_YUYV, V4L2_PIX_FMT_NV12}, false);
       }},
      {"v4l2_mjpeg_rig", [](const auto& dir, Clock*) { return MakeEmulated(dir, {V4L2_PIX_FMT_MJPEG}, true); }},
  };
}

INSTANTIATE_TEST_SUITE_P(V4l2, FrameSourceConformance, ::testing::ValuesIn(AllSources()), SourceCaseName);

}  // namespace
}  // namespace px::conformance

int main(int argc, char** argv) { return px::testing::RunTestsUnderUmockdev(argc, argv); }
