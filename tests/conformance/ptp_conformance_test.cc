// The conformance suite over the "ptp" source: the simulated PTP camera in process, and the same
// camera behind an emulated USB device driven by the real libusb transport (umockdev; that case
// skips with the reason when the test does not run under libumockdev-preload.so.0).
#include <memory>

#include "drivers/ptp/libusb_transport.h"
#include "drivers/ptp/ptp_source.h"
#include "tests/conformance/frame_source_conformance.h"
#include "tests/drivers/ptp_test_util.h"
#include "tests/drivers/ptp_umockdev_camera.h"

namespace px::conformance {
namespace {

using namespace px::ptp::testing;  // NOLINT: test helpers

StatusOr<std::unique_ptr<FrameSource>> MakeSimulatedPtp(Clock* clock) {
  auto responder = std::make_shared<PtpResponder>(HandHeldResponderOptions());
  return MakePtpSource(ResponderSourceOptions(responder, clock));
}

// Owns the emulated USB device for as long as the source lives.
class UsbCameraSource final : public FrameSource {
 public:
  UsbCameraSource(std::unique_ptr<UmockdevPtpCamera> camera, std::unique_ptr<FrameSource> source)
      : camera_(std::move(camera)), source_(std::move(source)) {}
  ~UsbCameraSource() override { source_.reset(); }  // release the interface before the device goes
  std::string_view Name() const override { return source_->Name(); }
  SourceDescription Describe() const override { return source_->Describe(); }
  StatusOr<ConfigureResult> Configure(const SourceConfig& wanted, SourceConfig* granted) override {
    return source_->Configure(wanted, granted);
  }
  StatusOr<FrameSet> Next(std::chrono::milliseconds timeout) override { return source_->Next(timeout); }
  void Stop() override { source_->Stop(); }

 private:
  std::unique_ptr<UmockdevPtpCamera> camera_;
  std::unique_ptr<FrameSource> source_;
};

StatusOr<std::unique_ptr<FrameSource>> MakeUsbPtp(Clock* clock) {
  PX_RETURN_IF_ERROR(CheckUmockdevEnvironment());
  auto responder = std::make_shared<PtpResponder>(HandHeldResponderOptions());
  PX_ASSIGN_OR_RETURN(std::unique_ptr<UmockdevPtpCamera> camera, UmockdevPtpCamera::Create(responder));
  PtpSourceOptions options;
  options.label = "usb 1d6b:0104";
  options.clock = clock;
  options.open_transport = [] { return ptp::OpenLibusbTransport({0x1d6b, 0x0104}); };
  PX_ASSIGN_OR_RETURN(std::unique_ptr<FrameSource> source, MakePtpSource(options));
  return std::unique_ptr<FrameSource>(std::make_unique<UsbCameraSource>(std::move(camera), std::move(source)));
}

INSTANTIATE_TEST_SUITE_P(
    Ptp,
    FrameSourceConformance,
    ::testing::Values(SourceCase{"ptp_simulated", [](const auto&, Clock* c) { return MakeSimulatedPtp(c); }},
                      SourceCase{"ptp_libusb_umockdev", [](const auto&, Clock* c) { return MakeUsbPtp(c); }}),
    SourceCaseName);

}  // namespace
}  // namespace px::conformance
