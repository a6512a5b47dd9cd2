// The real libusb transport against the simulated PTP camera behind an emulated USB device
// (umockdev: libusb's usbdevfs ioctls are answered by tests/drivers/ptp_umockdev_camera.h).
// Runs with LD_PRELOAD=libumockdev-preload.so.0 (ctest sets it); skips with the reason otherwise.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cerrno>

#include "device/source_registry.h"
#include "drivers/ptp/libusb_transport.h"
#include "tests/drivers/ptp_test_util.h"
#include "tests/drivers/ptp_umockdev_camera.h"

namespace px::ptp::testing {
namespace {

using std::chrono::milliseconds;
using ::testing::HasSubstr;

class PtpLibusb : public ::testing::Test {
 protected:
  void SetUp() override {
    if (Status env = CheckUmockdevEnvironment(); !env.ok()) GTEST_SKIP() << env.message();
  }

  void Plug(ResponderOptions options, UmockdevCameraOptions camera_options = {}) {
    responder_ = std::make_shared<PtpResponder>(std::move(options));
    auto camera = UmockdevPtpCamera::Create(responder_, camera_options);
    ASSERT_TRUE(camera.ok()) << camera.status().ToString();
    camera_ = std::move(camera).value();
  }

  std::unique_ptr<FrameSource> Source(LibusbTransportOptions usb, milliseconds shot_timeout = milliseconds(5000)) {
    PtpSourceOptions options;
    options.label = "usb camera";
    options.shot_timeout = shot_timeout;
    options.session.busy_backoff = milliseconds(5);
    options.session.transfer_timeout = milliseconds(3000);
    options.session.bulk_chunk_bytes = 16 * 1024;  // several transfers per JPEG
    options.open_transport = [usb] { return OpenLibusbTransport(usb); };
    auto source = MakePtpSource(options);
    EXPECT_TRUE(source.ok()) << source.status().ToString();
    return source.ok() ? std::move(source).value() : nullptr;
  }

  std::shared_ptr<PtpResponder> responder_;
  std::unique_ptr<UmockdevPtpCamera> camera_;
};

TEST_F(PtpLibusb, FindsTheStillImageInterfaceAndTalksPtp) {
  Plug(HandHeldResponderOptions());
  auto transport = OpenLibusbTransport({});
  ASSERT_TRUE(transport.ok()) << transport.status().ToString();
  EXPECT_EQ((*transport)->DeviceName(), "usb 001/005 (1d6b:0104)");
  EXPECT_EQ((*transport)->MaxPacketBytes(), 512u);
  PtpSession session(std::move(transport).value(), SessionOptions{});
  auto info = session.GetDeviceInfo();
  ASSERT_TRUE(info.ok()) << info.status().ToString();
  EXPECT_EQ(info->model, "Handheld PTP");
  EXPECT_TRUE(session.OpenSession().ok());
  EXPECT_TRUE(session.CloseSession().ok());
  EXPECT_EQ(camera_->counters().claims, 1);
  EXPECT_GE(camera_->counters().reaped, 6);  // 3 transactions: command, data/response URBs
}

TEST_F(PtpLibusb, AHandHeldCaptureOverUsb) {
  Plug(HandHeldResponderOptions());
  auto source = Source(*ParseVendorProduct("1d6b:0104"));
  ASSERT_TRUE(source);
  SourceConfig granted;
  ASSERT_TRUE(source->Configure(SourceConfig{PixelFormat::kRgb888, 0, 0, 3}, &granted).ok());
  EXPECT_EQ(granted.width, kShotWidth);
  auto frames = source->Next(milliseconds(30000));
  ASSERT_TRUE(frames.ok()) << frames.status().ToString();
  ASSERT_EQ(frames->frames.size(), 3u);
  FrameSet checked = *frames;
  EXPECT_TRUE(CheckFrameSet(granted, &checked).ok());
  EXPECT_EQ(checked.NumUsableFrames(), 3);
  EXPECT_THAT(source->Describe().model, HasSubstr("usb 001/005 (1d6b:0104)"));
  EXPECT_EQ(responder_->stats().objects_sent, 3);
  source->Stop();
  EXPECT_EQ(responder_->stats().sessions_closed, 1);
}

TEST_F(PtpLibusb, AClaimedCameraIsAPreconditionErrorThatSaysWhy) {
  UmockdevCameraOptions camera;
  camera.claim_errno = EBUSY;
  Plug(HandHeldResponderOptions(), camera);
  auto transport = OpenLibusbTransport({});
  ASSERT_FALSE(transport.ok());
  EXPECT_EQ(transport.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_THAT(transport.status().message(), HasSubstr("usb 001/005 (1d6b:0104)"));
  EXPECT_THAT(transport.status().message(), HasSubstr("LIBUSB_ERROR_BUSY"));
  EXPECT_THAT(transport.status().message(), HasSubstr("gvfs-gphoto2-volume-monitor"));
  EXPECT_THAT(transport.status().message(), HasSubstr("gphoto2"));
}

TEST_F(PtpLibusb, NoMatchingDeviceIsNotFound) {
  Plug(HandHeldResponderOptions());
  auto transport = OpenLibusbTransport(*ParseVendorProduct("04a9:3218"));
  ASSERT_FALSE(transport.ok());
  EXPECT_EQ(transport.status().code(), StatusCode::kNotFound);
  EXPECT_THAT(transport.status().message(), HasSubstr("04a9:3218"));
}

TEST_F(PtpLibusb, AVendorClassCameraIsFoundOnlyByItsIds) {
  UmockdevCameraOptions camera;
  camera.ptp_class = false;
  Plug(HandHeldResponderOptions(), camera);
  auto any = OpenLibusbTransport({});
  EXPECT_EQ(any.status().code(), StatusCode::kNotFound);
  auto by_id = OpenLibusbTransport(*ParseVendorProduct("1d6b:0104"));
  EXPECT_TRUE(by_id.ok()) << by_id.status().ToString();
}

TEST_F(PtpLibusb, UnpluggedMidCaptureOverUsb) {
  ResponderOptions options = HandHeldResponderOptions();
  options.unplug_after_objects = 1;
  Plug(options);
  auto source = Source({});
  ASSERT_TRUE(source);
  SourceConfig granted;
  ASSERT_TRUE(source->Configure(SourceConfig{PixelFormat::kRgb888, 0, 0, 3}, &granted).ok());
  auto frames = source->Next(milliseconds(30000));
  ASSERT_TRUE(frames.ok()) << frames.status().ToString();
  EXPECT_EQ(frames->NumUsableFrames(), 1);
  EXPECT_EQ(frames->frames[1].status, FrameStatus::kDropped);
  EXPECT_THAT(frames->frames[1].status_detail, HasSubstr("UNAVAILABLE"));
  EXPECT_THAT(frames->frames[1].status_detail, HasSubstr("usb 001/005 (1d6b:0104)"));
  EXPECT_THAT(frames->frames[1].status_detail, HasSubstr("LIBUSB_ERROR_NO_DEVICE"));
  auto next = source->Next(milliseconds(1000));
  EXPECT_EQ(next.status().code(), StatusCode::kUnavailable);
}

TEST_F(PtpLibusb, BusyThenNoEventOverUsb) {
  ResponderOptions options = HandHeldResponderOptions();
  options.busy_replies = 2;
  options.never_send_event = true;
  Plug(options);
  auto source = Source({}, milliseconds(400));
  ASSERT_TRUE(source);
  SourceConfig granted;
  ASSERT_TRUE(source->Configure(SourceConfig{PixelFormat::kRgb888, 0, 0, 2}, &granted).ok());
  auto frames = source->Next(milliseconds(10000));
  ASSERT_FALSE(frames.ok());
  EXPECT_EQ(frames.status().code(), StatusCode::kDeadlineExceeded);
  EXPECT_THAT(frames.status().message(), HasSubstr("ObjectAdded"));
  EXPECT_EQ(responder_->stats().busy_answers, 2);
  EXPECT_GE(camera_->counters().discarded, 1);  // the timed-out interrupt URB was cancelled
}

// The daemon's way in: source.kind "ptp" with the camera's ids, as parallaxd.json names it.
TEST_F(PtpLibusb, TheDaemonRegistryOpensTheCameraByItsIds) {
  Plug(HandHeldResponderOptions());
  device::SourceSettings settings;
  settings.kind = "ptp";
  settings.ptp.vendor_id = "1d6b";
  settings.ptp.product_id = "0104";
  settings.ptp.shots = 4;
  auto opened = device::OpenSource(settings);
  ASSERT_TRUE(opened.ok()) << opened.status().ToString();
  EXPECT_EQ(opened->source->Name(), "ptp");
  ASSERT_TRUE(opened->wanted.has_value());
  EXPECT_EQ(opened->wanted->shots, 4);
  SourceConfig granted;
  ASSERT_TRUE(opened->source->Configure(*opened->wanted, &granted).ok());
  auto frames = opened->source->Next(milliseconds(30000));
  ASSERT_TRUE(frames.ok()) << frames.status().ToString();
  EXPECT_EQ(frames->kind, FrameSetKind::kImageSet);
  EXPECT_EQ(frames->NumUsableFrames(), 4);

  // Another camera's ids: found nowhere, and the error says what was looked for.
  settings.ptp.product_id = "0105";
  auto other = device::OpenSource(settings);
  ASSERT_TRUE(other.ok());  // nothing is opened before Configure
  auto configured = other->source->Configure(*other->wanted, &granted);
  ASSERT_FALSE(configured.ok());
  EXPECT_EQ(configured.status().code(), StatusCode::kNotFound);
  EXPECT_THAT(configured.status().message(), HasSubstr("1d6b:0105"));
}

}  // namespace
}  // namespace px::ptp::testing
