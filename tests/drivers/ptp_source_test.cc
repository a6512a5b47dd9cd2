// The "ptp" FrameSource against the simulated camera serving hand-held shots of a small Pop9:
// a full capture, pixel formats, granted settings, DeviceBusy, a missing event, an unplugged
// camera mid-capture, refused operations and undecodable objects.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "tests/drivers/ptp_test_util.h"

namespace px::ptp::testing {
namespace {

using std::chrono::milliseconds;
using std::chrono::steady_clock;
using ::testing::HasSubstr;

cv::Mat FrameBgr(const Frame& frame) {
  cv::Mat view(frame.image.height, frame.image.width, CV_8UC3, const_cast<uint8_t*>(frame.image.bytes.data()));
  cv::Mat bgr;
  if (frame.image.format == PixelFormat::kRgb888) {
    cv::cvtColor(view, bgr, cv::COLOR_RGB2BGR);
  } else {
    bgr = view.clone();
  }
  return bgr;
}

struct Camera {
  explicit Camera(ResponderOptions options, Clock* clock = nullptr, milliseconds shot_timeout = milliseconds(5000)) {
    responder = std::make_shared<PtpResponder>(std::move(options));
    PtpSourceOptions source_options = ResponderSourceOptions(responder, clock);
    source_options.shot_timeout = shot_timeout;
    auto made = MakePtpSource(source_options);
    EXPECT_TRUE(made.ok()) << made.status().ToString();
    if (made.ok()) source = std::move(made).value();
  }

  SourceConfig Configure(int shots, PixelFormat format = PixelFormat::kRgb888) {
    SourceConfig wanted;
    wanted.pixel_format = format;
    wanted.shots = shots;
    SourceConfig granted;
    auto result = source->Configure(wanted, &granted);
    EXPECT_TRUE(result.ok()) << result.status().ToString();
    return granted;
  }

  std::shared_ptr<PtpResponder> responder;
  std::unique_ptr<FrameSource> source;
};

TEST(PtpSource, AHandHeldCaptureOfFiveShots) {
  ManualClock clock(1'000'000'000, 1'000);
  Camera camera(HandHeldResponderOptions(), &clock);
  const SourceConfig granted = camera.Configure(5);
  EXPECT_EQ(granted.shots, 5);
  EXPECT_EQ(granted.width, kShotWidth);
  EXPECT_EQ(granted.height, kShotHeight);
  EXPECT_EQ(granted.pixel_format, PixelFormat::kRgb888);

  const SourceDescription description = camera.source->Describe();
  EXPECT_EQ(description.kind, FrameSetKind::kImageSet);
  EXPECT_FALSE(description.rig.has_value());
  EXPECT_THAT(description.model, HasSubstr("Parallax Sim Handheld PTP"));
  EXPECT_THAT(description.model, HasSubstr("sim-ptp (1d6b:0104)"));

  auto frames = camera.source->Next(milliseconds(20000));
  ASSERT_TRUE(frames.ok()) << frames.status().ToString();
  EXPECT_EQ(frames->kind, FrameSetKind::kImageSet);
  ASSERT_EQ(frames->frames.size(), 5u);
  FrameSet checked = *frames;
  EXPECT_TRUE(CheckFrameSet(granted, &checked).ok());
  EXPECT_EQ(checked.NumUsableFrames(), 5);

  auto shots = RenderHandHeldShots(kShotWidth, kShotHeight);
  ASSERT_TRUE(shots.ok());
  for (size_t i = 0; i < frames->frames.size(); ++i) {
    const Frame& frame = frames->frames[i];
    EXPECT_EQ(frame.status, FrameStatus::kOk) << frame.status_detail;
    if (i > 0) {
      EXPECT_EQ(frame.sequence, frames->frames[i - 1].sequence + 1);
      EXPECT_GT(frame.timestamp_ns, frames->frames[i - 1].timestamp_ns);
    }
    // Shot i is the camera's i-th JPEG: the i-th view, through JPEG at quality 95.
    const double psnr = cv::PSNR(FrameBgr(frame), shots->bgr[i]);
    EXPECT_GT(psnr, 30.0) << "shot " << i;
    if (i + 1 < shots->bgr.size()) {
      EXPECT_LT(cv::PSNR(FrameBgr(frame), shots->bgr[i + 1]), psnr) << "shot " << i;
    }
  }
  const auto stats = camera.responder->stats();
  EXPECT_EQ(stats.captures, 5);
  EXPECT_EQ(stats.objects_sent, 5);
  EXPECT_EQ(stats.objects_deleted, 5);  // the card does not fill up
  camera.source->Stop();
  EXPECT_EQ(camera.responder->stats().sessions_closed, 1);
}

TEST(PtpSource, BgrFramesHaveOpenCvChannelOrder) {
  Camera camera(HandHeldResponderOptions());
  camera.Configure(2, PixelFormat::kBgr888);
  auto frames = camera.source->Next(milliseconds(20000));
  ASSERT_TRUE(frames.ok()) << frames.status().ToString();
  auto shots = RenderHandHeldShots(kShotWidth, kShotHeight);
  ASSERT_TRUE(shots.ok());
  const Frame& frame = frames->frames[0];
  EXPECT_EQ(frame.image.format, PixelFormat::kBgr888);
  cv::Mat raw(frame.image.height, frame.image.width, CV_8UC3, const_cast<uint8_t*>(frame.image.bytes.data()));
  EXPECT_GT(cv::PSNR(raw, shots->bgr[0]), 30.0);
}

TEST(PtpSource, ConfigureClampsShotsAndAdjustsFormatAndSize) {
  Camera camera(HandHeldResponderOptions());
  SourceConfig wanted;
  wanted.pixel_format = PixelFormat::kNv12;
  wanted.shots = 1;
  wanted.width = 17;
  wanted.height = 13;
  SourceConfig granted;
  auto result = camera.source->Configure(wanted, &granted);
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  EXPECT_EQ(*result, ConfigureResult::kAdjusted);
  EXPECT_EQ(granted.shots, kPtpMinShots);
  EXPECT_EQ(granted.pixel_format, PixelFormat::kRgb888);
  EXPECT_EQ(granted.width, kShotWidth);
  wanted.shots = 40;
  ASSERT_TRUE(camera.source->Configure(wanted, &granted).ok());
  EXPECT_EQ(granted.shots, kPtpMaxShots);
  SourceConfig exact{PixelFormat::kBgr888, kShotWidth, kShotHeight, 9};
  auto valid = camera.source->Configure(exact, &granted);
  ASSERT_TRUE(valid.ok());
  EXPECT_EQ(*valid, ConfigureResult::kValid);
  EXPECT_EQ(camera.responder->stats().sessions_opened, 1);  // reconfiguring keeps the session
}

TEST(PtpSource, ACameraWithoutImageSizeGrantsAnySize) {
  ResponderOptions options = HandHeldResponderOptions();
  options.image_width = 0;
  options.image_height = 0;
  Camera camera(options);
  const SourceConfig granted = camera.Configure(3);
  EXPECT_EQ(granted.width, 0);
  auto frames = camera.source->Next(milliseconds(20000));
  ASSERT_TRUE(frames.ok()) << frames.status().ToString();
  EXPECT_EQ(frames->NumUsableFrames(), 3);
  EXPECT_EQ(frames->frames[0].image.width, kShotWidth);
}

TEST(PtpSource, DeviceBusyIsRetriedWithinACapture) {
  ResponderOptions options = HandHeldResponderOptions();
  options.busy_replies = 3;
  Camera camera(options);
  camera.Configure(3);
  auto frames = camera.source->Next(milliseconds(20000));
  ASSERT_TRUE(frames.ok()) << frames.status().ToString();
  EXPECT_EQ(frames->NumUsableFrames(), 3);
  EXPECT_EQ(camera.responder->stats().busy_answers, 3);
}

TEST(PtpSource, ACameraThatNeverSendsTheEventHitsTheDeadline) {
  ResponderOptions options = HandHeldResponderOptions();
  options.never_send_event = true;
  Camera camera(options, nullptr, milliseconds(300));
  camera.Configure(3);
  const auto start = steady_clock::now();
  auto frames = camera.source->Next(milliseconds(20000));
  const auto waited = std::chrono::duration_cast<milliseconds>(steady_clock::now() - start);
  ASSERT_FALSE(frames.ok());
  EXPECT_EQ(frames.status().code(), StatusCode::kDeadlineExceeded);
  EXPECT_THAT(frames.status().message(), HasSubstr("shot 1 of 3"));
  EXPECT_THAT(frames.status().message(), HasSubstr("ObjectAdded (0x4002)"));
  EXPECT_LT(waited.count(), 3000);
  // The overall timeout bounds the capture too.
  auto short_frames = camera.source->Next(milliseconds(100));
  ASSERT_FALSE(short_frames.ok());
  EXPECT_EQ(short_frames.status().code(), StatusCode::kDeadlineExceeded);
}

TEST(PtpSource, UnpluggedMidCaptureKeepsTheShotsTaken) {
  ResponderOptions options = HandHeldResponderOptions();
  options.unplug_after_objects = 2;
  Camera camera(options);
  camera.Configure(5);
  auto frames = camera.source->Next(milliseconds(20000));
  ASSERT_TRUE(frames.ok()) << frames.status().ToString();
  ASSERT_EQ(frames->frames.size(), 5u);
  EXPECT_EQ(frames->NumUsableFrames(), 2);
  for (int i = 0; i < 2; ++i) EXPECT_EQ(frames->frames[i].status, FrameStatus::kOk);
  for (int i = 2; i < 5; ++i) {
    const Frame& frame = frames->frames[i];
    EXPECT_EQ(frame.status, FrameStatus::kDropped);
    EXPECT_THAT(frame.status_detail, HasSubstr("shot " + std::to_string(i + 1) + " of 5 not taken"));
    EXPECT_THAT(frame.status_detail, HasSubstr("UNAVAILABLE"));
    EXPECT_THAT(frame.status_detail, HasSubstr("sim-ptp (1d6b:0104)"));
  }
  // The camera is gone: the next capture says so at once, naming it.
  auto next = camera.source->Next(milliseconds(2000));
  ASSERT_FALSE(next.ok());
  EXPECT_EQ(next.status().code(), StatusCode::kUnavailable);
  EXPECT_THAT(next.status().message(), HasSubstr("sim-ptp (1d6b:0104)"));
  EXPECT_THAT(next.status().message(), HasSubstr("disconnected"));
  // And reconnecting fails while it stays unplugged.
  SourceConfig granted;
  auto reconfigured = camera.source->Configure(SourceConfig{PixelFormat::kRgb888, 0, 0, 5}, &granted);
  EXPECT_EQ(reconfigured.status().code(), StatusCode::kUnavailable);
  camera.source->Stop();  // after a loss, Stop is still safe
}

TEST(PtpSource, UnpluggedBeforeTheFirstShotIsUnavailable) {
  ResponderOptions options = HandHeldResponderOptions();
  options.unplug_after_objects = 0;
  Camera camera(options);
  camera.Configure(3);
  auto frames = camera.source->Next(milliseconds(20000));
  ASSERT_FALSE(frames.ok());
  EXPECT_EQ(frames.status().code(), StatusCode::kUnavailable);
  EXPECT_THAT(frames.status().message(), HasSubstr("sim-ptp (1d6b:0104)"));
  EXPECT_THAT(frames.status().message(), HasSubstr("LIBUSB_ERROR_NO_DEVICE"));
}

TEST(PtpSource, ARefusedOperationFailsTheCaptureNamingIt) {
  ResponderOptions options = HandHeldResponderOptions();
  options.fail_operation = op::kGetObjectInfo;
  options.fail_response = rc::kGeneralError;
  Camera camera(options);
  camera.Configure(2);
  auto frames = camera.source->Next(milliseconds(20000));
  ASSERT_FALSE(frames.ok());
  EXPECT_EQ(frames.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_THAT(frames.status().message(), HasSubstr("GetObjectInfo (0x1008)"));
  EXPECT_THAT(frames.status().message(), HasSubstr("GeneralError (0x2002)"));
}

TEST(PtpSource, ACameraWithoutRemoteCaptureIsRefusedAtConfigure) {
  ResponderOptions options = HandHeldResponderOptions();
  options.fail_operation = op::kOpenSession;
  options.fail_response = rc::kAccessDenied;
  Camera camera(options);
  SourceConfig granted;
  auto result = camera.source->Configure(SourceConfig{PixelFormat::kRgb888, 0, 0, 3}, &granted);
  ASSERT_FALSE(result.ok());
  EXPECT_THAT(result.status().message(), HasSubstr("OpenSession (0x1002)"));
  EXPECT_THAT(result.status().message(), HasSubstr("AccessDenied (0x200F)"));
}

TEST(PtpSource, UndecodableObjectsAreMarkedCorrupt) {
  ResponderOptions options = HandHeldResponderOptions();
  options.jpegs = {std::vector<uint8_t>(5000, 0x42), options.jpegs[0]};
  Camera camera(options);
  camera.Configure(2);
  auto frames = camera.source->Next(milliseconds(20000));
  ASSERT_TRUE(frames.ok()) << frames.status().ToString();
  EXPECT_EQ(frames->frames[0].status, FrameStatus::kCorrupt);
  EXPECT_THAT(frames->frames[0].status_detail, HasSubstr("IMG_0001.JPG, 5000 bytes"));
  EXPECT_EQ(frames->frames[1].status, FrameStatus::kOk);
}

TEST(PtpSource, NextBeforeConfigureAndAfterStopIsAPreconditionError) {
  Camera camera(HandHeldResponderOptions());
  EXPECT_EQ(camera.source->Next(milliseconds(100)).status().code(), StatusCode::kFailedPrecondition);
  camera.Configure(2);
  camera.source->Stop();
  camera.source->Stop();
  EXPECT_EQ(camera.source->Next(milliseconds(100)).status().code(), StatusCode::kFailedPrecondition);
  camera.Configure(2);
  EXPECT_TRUE(camera.source->Next(milliseconds(20000)).ok());
  EXPECT_EQ(camera.responder->stats().sessions_opened, 2);
}

}  // namespace
}  // namespace px::ptp::testing
