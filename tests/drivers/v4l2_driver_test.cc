// The V4L2 driver against an emulated camera (umockdev) that serves a real simulated Pop9
// lattice frame: discovery, format negotiation, mmap streaming, conversion of every format back
// to the source image, short buffers, a camera that vanishes or stalls, a busy device, controls.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "drivers/v4l2/v4l2_discovery.h"
#include "drivers/v4l2/v4l2_source.h"
#include "tests/drivers/emulated_v4l2_device.h"
#include "tests/drivers/sim_lattice_frame.h"
#include "tests/testing/temp_dir.h"

namespace px {
namespace {

using std::chrono::milliseconds;
using testing::EmulatedCameraOptions;
using testing::EmulatedV4l2Camera;

constexpr int kSensorWidth = 504;   // 3 x 160 + 4 x 6
constexpr int kSensorHeight = 384;  // 3 x 120 + 4 x 6

double Psnr(const cv::Mat& a, const cv::Mat& b) { return cv::PSNR(a, b); }

class V4l2DriverTest : public ::testing::Test {
 protected:
  void SetUp() override {
    auto testbed = testing::EmulatedV4l2Testbed::Create();
    if (!testbed.ok()) GTEST_SKIP() << testbed.status().message();
    testbed_ = std::move(testbed).value();
    auto frame = testing::SmallPop9FrameBgr();
    ASSERT_TRUE(frame.ok()) << frame.status().ToString();
    frame_ = *frame;
    ASSERT_EQ(frame_.cols, kSensorWidth);
    ASSERT_EQ(frame_.rows, kSensorHeight);
  }

  EmulatedV4l2Camera* AddCamera(const EmulatedCameraOptions& options = {}) {
    auto camera = testbed_->AddCamera(options, frame_);
    EXPECT_TRUE(camera.ok()) << camera.status().ToString();
    return camera.ok() ? *camera : nullptr;
  }

  std::unique_ptr<V4l2Source> Open(const std::string& device, V4l2SourceOptions options = {}) {
    options.device = device;
    auto source = OpenV4l2Source(options);
    EXPECT_TRUE(source.ok()) << source.status().ToString();
    return source.ok() ? std::move(source).value() : nullptr;
  }

  // Configures `format` at the native size and captures one frame set.
  StatusOr<FrameSet> CaptureOne(V4l2Source* source, PixelFormat format, SourceConfig* granted) {
    PX_ASSIGN_OR_RETURN(ConfigureResult result, source->Configure(SourceConfig{format}, granted));
    (void)result;
    return source->Next(milliseconds(2000));
  }

  px::testing::TempDir dir_;
  std::unique_ptr<testing::EmulatedV4l2Testbed> testbed_;
  cv::Mat frame_;
};

// --- discovery ---------------------------------------------------------------------------

TEST_F(V4l2DriverTest, DiscoveryListsCamerasAndSaysWhyOtherNodesAreSkipped) {
  EmulatedCameraOptions lattice;
  lattice.sizes = {{kSensorWidth, kSensorHeight}, {kSensorWidth / 2, kSensorHeight / 2}};
  ASSERT_NE(AddCamera(lattice), nullptr);
  EmulatedCameraOptions output;
  output.node = "video1";
  output.device_caps = V4L2_CAP_VIDEO_OUTPUT | V4L2_CAP_STREAMING;
  ASSERT_NE(AddCamera(output), nullptr);
  EmulatedCameraOptions mplane;
  mplane.node = "video2";
  mplane.device_caps = V4L2_CAP_VIDEO_CAPTURE_MPLANE | V4L2_CAP_STREAMING;
  ASSERT_NE(AddCamera(mplane), nullptr);
  ASSERT_TRUE(testbed_->AddPlainNode("video10").ok());

  auto discovery = v4l2::DiscoverDevices("/dev");
  ASSERT_TRUE(discovery.ok()) << discovery.status().ToString();
  ASSERT_EQ(discovery->cameras.size(), 1u);
  const v4l2::DeviceInfo& camera = discovery->cameras[0];
  EXPECT_EQ(camera.path, "/dev/video0");
  EXPECT_EQ(camera.name, "Parallax emulated Pop9");
  EXPECT_EQ(camera.driver, "px_emulated");
  EXPECT_EQ(camera.bus_info, "platform:px-emulated");
  ASSERT_EQ(camera.formats.size(), 6u);
  EXPECT_EQ(v4l2::FourccName(camera.formats[0].fourcc), "YUYV");
  EXPECT_EQ(v4l2::FourccName(camera.formats[2].fourcc), "MJPG");
  EXPECT_TRUE(camera.formats[2].compressed);
  ASSERT_EQ(camera.formats[0].sizes.size(), 2u);
  EXPECT_EQ(camera.formats[0].sizes[0], (v4l2::FrameSize{kSensorWidth, kSensorHeight}));  // largest first
  EXPECT_EQ(camera.formats[0].sizes[1], (v4l2::FrameSize{kSensorWidth / 2, kSensorHeight / 2}));

  ASSERT_EQ(discovery->skipped.size(), 3u);
  EXPECT_EQ(discovery->skipped[0].path, "/dev/video1");
  EXPECT_NE(discovery->skipped[0].reason.find("video output only"), std::string::npos) << discovery->skipped[0].reason;
  EXPECT_EQ(discovery->skipped[1].path, "/dev/video2");
  EXPECT_NE(discovery->skipped[1].reason.find("multi-planar"), std::string::npos) << discovery->skipped[1].reason;
  EXPECT_EQ(discovery->skipped[2].path, "/dev/video10");  // natural order: 10 after 2
  EXPECT_NE(discovery->skipped[2].reason.find("not a V4L2 device"), std::string::npos) << discovery->skipped[2].reason;
}

TEST_F(V4l2DriverTest, OpeningSomethingElseSaysWhatIsWrong) {
  EmulatedCameraOptions output;
  output.device_caps = V4L2_CAP_VIDEO_OUTPUT | V4L2_CAP_STREAMING;
  ASSERT_NE(AddCamera(output), nullptr);
  V4l2SourceOptions options;
  options.device = "/dev/video0";
  auto source = OpenV4l2Source(options);
  ASSERT_FALSE(source.ok());
  EXPECT_EQ(source.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(source.status().message().find("v4l2:/dev/video0: not a usable camera: video output only"),
            std::string::npos)
      << source.status().message();

  options.device = "/dev/video7";
  source = OpenV4l2Source(options);
  ASSERT_FALSE(source.ok());
  EXPECT_EQ(source.status().code(), StatusCode::kNotFound) << source.status().ToString();
  EXPECT_NE(source.status().message().find("/dev/video7"), std::string::npos);
}

// --- negotiation -------------------------------------------------------------------------

TEST_F(V4l2DriverTest, GrantsAnOfferedFormatAtTheNativeSize) {
  ASSERT_NE(AddCamera(), nullptr);
  auto source = Open("/dev/video0");
  ASSERT_NE(source, nullptr);
  SourceConfig granted;
  auto result = source->Configure(SourceConfig{PixelFormat::kYuyv}, &granted);
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  EXPECT_EQ(*result, ConfigureResult::kValid);
  EXPECT_EQ(granted, (SourceConfig{PixelFormat::kYuyv, kSensorWidth, kSensorHeight, 1}));
  EXPECT_EQ(v4l2::FourccName(source->Layout().fourcc), "YUYV");
  EXPECT_EQ(source->Layout().bytes_per_line, uint32_t{kSensorWidth * 2 + 24});  // the device pads rows
}

TEST_F(V4l2DriverTest, AdjustsSizeAndFormatToWhatTheDeviceGrants) {
  EmulatedCameraOptions options;
  options.fourccs = {V4L2_PIX_FMT_YUYV, V4L2_PIX_FMT_NV12};
  options.sizes = {{kSensorWidth, kSensorHeight}, {kSensorWidth / 2, kSensorHeight / 2}};
  EmulatedV4l2Camera* camera = AddCamera(options);
  ASSERT_NE(camera, nullptr);
  auto source = Open("/dev/video0");
  ASSERT_NE(source, nullptr);

  SourceConfig granted;
  auto result = source->Configure(SourceConfig{PixelFormat::kNv12, 640, 480}, &granted);
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  EXPECT_EQ(*result, ConfigureResult::kAdjusted);
  EXPECT_EQ(granted, (SourceConfig{PixelFormat::kNv12, kSensorWidth, kSensorHeight, 1}));

  result = source->Configure(SourceConfig{PixelFormat::kNv12, 200, 150}, &granted);
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  EXPECT_EQ(*result, ConfigureResult::kAdjusted);
  EXPECT_EQ(granted, (SourceConfig{PixelFormat::kNv12, kSensorWidth / 2, kSensorHeight / 2, 1}));
  auto frames = source->Next(milliseconds(2000));
  ASSERT_TRUE(frames.ok()) << frames.status().ToString();
  EXPECT_EQ(frames->frames[0].status, FrameStatus::kOk) << frames->frames[0].status_detail;
  EXPECT_EQ(frames->frames[0].image.width, kSensorWidth / 2);

  // GRAY8 is not offered and cannot be made losslessly: the device's best format instead.
  result = source->Configure(SourceConfig{PixelFormat::kGray8}, &granted);
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  EXPECT_EQ(*result, ConfigureResult::kAdjusted);
  EXPECT_EQ(granted.pixel_format, PixelFormat::kYuyv);
  EXPECT_EQ(camera->Fourcc(), uint32_t{V4L2_PIX_FMT_YUYV});
}

TEST_F(V4l2DriverTest, FollowsADriverThatSetsAnotherFormatThanAskedFor) {
  EmulatedV4l2Camera* camera = AddCamera();
  ASSERT_NE(camera, nullptr);
  camera->SetDriverFourccOverride(V4L2_PIX_FMT_YUYV);  // TRY_FMT says NV12, S_FMT sets YUYV
  auto source = Open("/dev/video0");
  ASSERT_NE(source, nullptr);
  SourceConfig granted;
  auto result = source->Configure(SourceConfig{PixelFormat::kNv12}, &granted);
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  EXPECT_EQ(*result, ConfigureResult::kAdjusted);
  EXPECT_EQ(granted.pixel_format, PixelFormat::kYuyv);
  auto frames = source->Next(milliseconds(2000));
  ASSERT_TRUE(frames.ok()) << frames.status().ToString();
  EXPECT_EQ(frames->frames[0].status, FrameStatus::kOk) << frames->frames[0].status_detail;
  EXPECT_EQ(frames->frames[0].image.bytes, camera->PackedFrame());
}

TEST_F(V4l2DriverTest, RefusesADeviceWithNothingItCanReadAndListsWhatItOffers) {
  EmulatedCameraOptions options;
  options.fourccs = {V4L2_PIX_FMT_H264, V4L2_PIX_FMT_SBGGR10};
  ASSERT_NE(AddCamera(options), nullptr);
  auto source = Open("/dev/video0");
  ASSERT_NE(source, nullptr);
  SourceConfig granted;
  auto result = source->Configure(SourceConfig{PixelFormat::kRgb888}, &granted);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().code(), StatusCode::kInvalidArgument);
  const std::string message = result.status().message();
  EXPECT_NE(message.find("v4l2:/dev/video0: cannot deliver RGB888"), std::string::npos) << message;
  EXPECT_NE(message.find("H264 504x384; BG10 504x384"), std::string::npos) << message;
  EXPECT_NE(message.find("the driver reads RGB3, BGR3, GREY, YUYV, NV12, RGGB, MJPG"), std::string::npos) << message;
  EXPECT_EQ(source->Next(milliseconds(100)).status().code(), StatusCode::kFailedPrecondition);
}

// --- the rig calibration -------------------------------------------------------------------

TEST_F(V4l2DriverTest, ReportsTheRigCalibrationAndHoldsTheSensorToIt) {
  EmulatedCameraOptions options;
  options.sizes = {{kSensorWidth / 2, kSensorHeight / 2}, {kSensorWidth, kSensorHeight}};
  ASSERT_NE(AddCamera(options), nullptr);
  const auto rig_file = dir_.path() / "rig.json";
  ASSERT_TRUE(testing::WriteSmallPop9Calibration(rig_file).ok());
  V4l2SourceOptions source_options;
  source_options.rig_calibration = rig_file;
  auto source = Open("/dev/video0", source_options);
  ASSERT_NE(source, nullptr);

  SourceDescription description = source->Describe();
  EXPECT_EQ(description.model, "v4l2:/dev/video0");
  EXPECT_EQ(description.kind, FrameSetKind::kLatticeFrame);
  ASSERT_TRUE(description.rig.has_value());
  EXPECT_EQ(description.rig->NumViews(), 9);
  EXPECT_EQ(description.rig->lattice.sensor_width, kSensorWidth);

  // Native means the calibrated sensor size, not the first size the device lists.
  SourceConfig granted;
  auto result = source->Configure(SourceConfig{PixelFormat::kRgb888}, &granted);
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  EXPECT_EQ(granted.width, kSensorWidth);
  EXPECT_EQ(granted.height, kSensorHeight);

  // A binned frame does not fit the calibrated lattice.
  result = source->Configure(SourceConfig{PixelFormat::kRgb888, kSensorWidth / 2, kSensorHeight / 2}, &granted);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(result.status().message().find("is calibrated for 504x384"), std::string::npos)
      << result.status().message();
}

TEST_F(V4l2DriverTest, ABadRigCalibrationFileIsNamed) {
  ASSERT_NE(AddCamera(), nullptr);
  const auto rig_file = dir_.path() / "rig.json";
  std::ofstream(rig_file) << R"({"schema_version": 1, "rig_name": "x"})";
  V4l2SourceOptions options;
  options.rig_calibration = rig_file;
  auto source = OpenV4l2Source(options);
  ASSERT_FALSE(source.ok());
  EXPECT_EQ(source.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(source.status().message().find(rig_file.string()), std::string::npos) << source.status().message();

  options.rig_calibration = dir_.path() / "absent.json";
  source = OpenV4l2Source(options);
  ASSERT_FALSE(source.ok());
  EXPECT_EQ(source.status().code(), StatusCode::kNotFound) << source.status().ToString();
}

// --- streaming -------------------------------------------------------------------------------

TEST_F(V4l2DriverTest, StreamsLatticeFramesWithIncreasingSequence) {
  EmulatedV4l2Camera* camera = AddCamera();
  ASSERT_NE(camera, nullptr);
  auto source = Open("/dev/video0");
  ASSERT_NE(source, nullptr);
  SourceConfig granted;
  ASSERT_TRUE(source->Configure(SourceConfig{PixelFormat::kYuyv}, &granted).ok());
  EXPECT_TRUE(camera->Streaming());

  uint64_t last_sequence = 0;
  int64_t last_timestamp = 0;
  for (int i = 0; i < 6; ++i) {
    auto frames = source->Next(milliseconds(2000));
    ASSERT_TRUE(frames.ok()) << frames.status().ToString();
    EXPECT_EQ(frames->kind, FrameSetKind::kLatticeFrame);
    EXPECT_EQ(frames->capture_id, static_cast<uint64_t>(i + 1));
    ASSERT_EQ(frames->frames.size(), 1u);
    const Frame& frame = frames->frames[0];
    EXPECT_EQ(frame.status, FrameStatus::kOk) << frame.status_detail;
    EXPECT_TRUE(frame.image.Validate().ok());
    if (i > 0) {
      EXPECT_GT(frame.sequence, last_sequence);
      EXPECT_GE(frame.timestamp_ns, last_timestamp);
    }
    EXPECT_GT(frame.timestamp_ns, 0);
    last_sequence = frame.sequence;
    last_timestamp = frame.timestamp_ns;
  }
  // Frames waiting in the queue are dropped: each capture is taken after its call.
  EXPECT_GE(last_sequence, 5u);
  EXPECT_GT(camera->FramesServed(), 6u);

  source->Stop();
  EXPECT_FALSE(camera->Streaming());
  EXPECT_EQ(source->Next(milliseconds(100)).status().code(), StatusCode::kFailedPrecondition);
}

// --- conversion --------------------------------------------------------------------------

struct ConversionCase {
  const char* name;
  uint32_t device_fourcc;
  PixelFormat wanted;
  bool exact_bytes;    // the image is the device's encoding, rows unpadded
  double min_psnr_db;  // decoded to BGR, against the served image
};

class V4l2ConversionTest : public V4l2DriverTest, public ::testing::WithParamInterface<ConversionCase> {};

TEST_P(V4l2ConversionTest, DeliversTheSourceImage) {
  const ConversionCase& c = GetParam();
  EmulatedCameraOptions options;
  options.fourccs = {c.device_fourcc};
  EmulatedV4l2Camera* camera = AddCamera(options);
  ASSERT_NE(camera, nullptr);
  auto source = Open("/dev/video0");
  ASSERT_NE(source, nullptr);
  SourceConfig granted;
  auto result = source->Configure(SourceConfig{c.wanted}, &granted);
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  EXPECT_EQ(*result, ConfigureResult::kValid);
  EXPECT_EQ(granted.pixel_format, c.wanted);
  auto frames = source->Next(milliseconds(2000));
  ASSERT_TRUE(frames.ok()) << frames.status().ToString();
  const Frame& frame = frames->frames[0];
  ASSERT_EQ(frame.status, FrameStatus::kOk) << frame.status_detail;
  ASSERT_TRUE(frame.image.Validate().ok()) << frame.image.Validate().ToString();
  EXPECT_EQ(frame.image.format, c.wanted);

  if (c.exact_bytes) {
    EXPECT_TRUE(frame.image.bytes == camera->PackedFrame()) << "bytes differ from the device's";
  }
  auto bgr = ToBgr(frame.image);
  ASSERT_TRUE(bgr.ok()) << bgr.status().ToString();
  cv::Mat served = camera->SourceBgr();
  if (c.wanted == PixelFormat::kGray8) {  // a grey camera can only be compared in grey
    cv::cvtColor(served, served, cv::COLOR_BGR2GRAY);
    cv::cvtColor(served, served, cv::COLOR_GRAY2BGR);
  }
  const double psnr = Psnr(*bgr, served);
  EXPECT_GE(psnr, c.min_psnr_db) << c.name;
  // The same comparison against the image shifted by one tile column fails: PSNR measures content.
  cv::Mat shifted;
  cv::warpAffine(served, shifted, cv::Mat_<double>({2, 3}, {1, 0, 166, 0, 1, 0}), served.size());
  EXPECT_LT(Psnr(*bgr, shifted), c.min_psnr_db - 5) << c.name;
  RecordProperty("psnr_db", std::to_string(psnr));
  std::printf("%s: %.1f dB against the served image\n", c.name, psnr);
}

INSTANTIATE_TEST_SUITE_P(
    Formats,
    V4l2ConversionTest,
    ::testing::Values(ConversionCase{"yuyv", V4L2_PIX_FMT_YUYV, PixelFormat::kYuyv, true, 30},
                      ConversionCase{"nv12", V4L2_PIX_FMT_NV12, PixelFormat::kNv12, true, 28},
                      ConversionCase{"bayer_rggb8", V4L2_PIX_FMT_SRGGB8, PixelFormat::kBayerRggb8, true, 24},
                      ConversionCase{"grey", V4L2_PIX_FMT_GREY, PixelFormat::kGray8, true, 40},
                      ConversionCase{"bgr24", V4L2_PIX_FMT_BGR24, PixelFormat::kBgr888, true, 99},
                      ConversionCase{"rgb24_as_bgr", V4L2_PIX_FMT_RGB24, PixelFormat::kBgr888, false, 99},
                      ConversionCase{"bgr24_as_rgb", V4L2_PIX_FMT_BGR24, PixelFormat::kRgb888, false, 99},
                      ConversionCase{"mjpeg_as_bgr", V4L2_PIX_FMT_MJPEG, PixelFormat::kBgr888, false, 32},
                      ConversionCase{"mjpeg_as_rgb", V4L2_PIX_FMT_MJPEG, PixelFormat::kRgb888, false, 32}),
    [](const ::testing::TestParamInfo<ConversionCase>& param) { return std::string(param.param.name); });

// --- faults ------------------------------------------------------------------------------

TEST_F(V4l2DriverTest, AShortBufferIsACorruptFrameNotACrash) {
  EmulatedV4l2Camera* camera = AddCamera();
  ASSERT_NE(camera, nullptr);
  auto source = Open("/dev/video0");
  ASSERT_NE(source, nullptr);
  SourceConfig granted;
  ASSERT_TRUE(source->Configure(SourceConfig{PixelFormat::kYuyv}, &granted).ok());
  camera->ShortenFrames(1000);
  auto frames = source->Next(milliseconds(2000));
  ASSERT_TRUE(frames.ok()) << frames.status().ToString();
  EXPECT_EQ(frames->frames[0].status, FrameStatus::kCorrupt);
  EXPECT_NE(frames->frames[0].status_detail.find("short buffer: 1000 bytes"), std::string::npos)
      << frames->frames[0].status_detail;
  EXPECT_EQ(frames->NumUsableFrames(), 0);
  FrameSet checked = *frames;
  EXPECT_EQ(CheckFrameSet(granted, &checked).code(), StatusCode::kDataLoss);
  // Whole frames again once the transfer recovers.
  camera->ShortenFrames(0);
  frames = source->Next(milliseconds(2000));
  ASSERT_TRUE(frames.ok()) << frames.status().ToString();
  EXPECT_EQ(frames->frames[0].status, FrameStatus::kOk) << frames->frames[0].status_detail;
}

TEST_F(V4l2DriverTest, ATruncatedJpegIsACorruptFrame) {
  EmulatedCameraOptions options;
  options.fourccs = {V4L2_PIX_FMT_MJPEG};
  EmulatedV4l2Camera* camera = AddCamera(options);
  ASSERT_NE(camera, nullptr);
  auto source = Open("/dev/video0");
  ASSERT_NE(source, nullptr);
  SourceConfig granted;
  ASSERT_TRUE(source->Configure(SourceConfig{PixelFormat::kBgr888}, &granted).ok());
  camera->ShortenFrames(static_cast<uint32_t>(camera->PackedFrame().size() / 2));
  auto frames = source->Next(milliseconds(2000));
  ASSERT_TRUE(frames.ok()) << frames.status().ToString();
  EXPECT_EQ(frames->frames[0].status, FrameStatus::kCorrupt);
  EXPECT_NE(frames->frames[0].status_detail.find("truncated"), std::string::npos) << frames->frames[0].status_detail;
}

TEST_F(V4l2DriverTest, ACameraThatVanishesMidCaptureIsUnavailable) {
  EmulatedV4l2Camera* camera = AddCamera();
  ASSERT_NE(camera, nullptr);
  auto source = Open("/dev/video0");
  ASSERT_NE(source, nullptr);
  SourceConfig granted;
  ASSERT_TRUE(source->Configure(SourceConfig{PixelFormat::kNv12}, &granted).ok());
  ASSERT_TRUE(source->Next(milliseconds(2000)).ok());

  camera->SetVanished(true);
  auto frames = source->Next(milliseconds(2000));
  ASSERT_FALSE(frames.ok());
  EXPECT_EQ(frames.status().code(), StatusCode::kUnavailable);
  EXPECT_NE(frames.status().message().find("v4l2:/dev/video0: camera vanished"), std::string::npos)
      << frames.status().message();
  EXPECT_NE(frames.status().message().find("No such device"), std::string::npos) << frames.status().message();
  // It stays gone, and configuring again says so too.
  EXPECT_EQ(source->Next(milliseconds(100)).status().code(), StatusCode::kUnavailable);
  EXPECT_EQ(source->Configure(SourceConfig{PixelFormat::kNv12}, &granted).status().code(), StatusCode::kUnavailable);

  // Plugged back in: a new Configure brings it back.
  camera->SetVanished(false);
  auto replugged = source->Configure(SourceConfig{PixelFormat::kNv12}, &granted);
  ASSERT_TRUE(replugged.ok()) << replugged.status().ToString();
  auto again = source->Next(milliseconds(2000));
  ASSERT_TRUE(again.ok()) << again.status().ToString();
  EXPECT_EQ(again->frames[0].status, FrameStatus::kOk);
}

TEST_F(V4l2DriverTest, NoFrameInTimeIsADeadlineError) {
  EmulatedV4l2Camera* camera = AddCamera();
  ASSERT_NE(camera, nullptr);
  auto source = Open("/dev/video0");
  ASSERT_NE(source, nullptr);
  SourceConfig granted;
  ASSERT_TRUE(source->Configure(SourceConfig{PixelFormat::kYuyv}, &granted).ok());
  camera->SetStalled(true);
  const auto start = std::chrono::steady_clock::now();
  auto frames = source->Next(milliseconds(200));
  const auto elapsed = std::chrono::steady_clock::now() - start;
  ASSERT_FALSE(frames.ok());
  EXPECT_EQ(frames.status().code(), StatusCode::kDeadlineExceeded);
  EXPECT_NE(frames.status().message().find("v4l2:/dev/video0: no frame within 200 ms"), std::string::npos)
      << frames.status().message();
  EXPECT_GE(elapsed, milliseconds(200));
  EXPECT_LT(elapsed, milliseconds(1500));
  camera->SetStalled(false);
  EXPECT_TRUE(source->Next(milliseconds(2000)).ok());
}

TEST_F(V4l2DriverTest, ADeviceHeldByAnotherProgramIsAPreconditionError) {
  ASSERT_NE(AddCamera(), nullptr);
  auto first = Open("/dev/video0");
  auto second = Open("/dev/video0");
  ASSERT_NE(first, nullptr);
  ASSERT_NE(second, nullptr);
  SourceConfig granted;
  ASSERT_TRUE(first->Configure(SourceConfig{PixelFormat::kYuyv}, &granted).ok());
  auto result = second->Configure(SourceConfig{PixelFormat::kYuyv}, &granted);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(result.status().message().find("v4l2:/dev/video0: in use by another program"), std::string::npos)
      << result.status().message();
  // Released, the camera is the second one's.
  first->Stop();
  ASSERT_TRUE(second->Configure(SourceConfig{PixelFormat::kYuyv}, &granted).ok());
  EXPECT_TRUE(second->Next(milliseconds(2000)).ok());
}

// --- controls ----------------------------------------------------------------------------

const v4l2::ControlState* FindControl(const std::vector<v4l2::ControlState>& controls, const std::string& name) {
  for (const auto& control : controls) {
    if (control.name == name) return &control;
  }
  return nullptr;
}

TEST_F(V4l2DriverTest, SetsExposureAndGainInManualMode) {
  EmulatedV4l2Camera* camera = AddCamera();
  ASSERT_NE(camera, nullptr);
  V4l2SourceOptions options;
  options.controls.exposure = 300;
  options.controls.gain = 64;
  auto source = Open("/dev/video0", options);
  ASSERT_NE(source, nullptr);
  SourceConfig granted;
  auto result = source->Configure(SourceConfig{PixelFormat::kYuyv}, &granted);
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  EXPECT_EQ(camera->Control(V4L2_CID_EXPOSURE_AUTO), V4L2_EXPOSURE_MANUAL);
  EXPECT_EQ(camera->Control(V4L2_CID_EXPOSURE_ABSOLUTE), 300);
  EXPECT_EQ(camera->Control(V4L2_CID_GAIN), 64);
  // Manual mode first: the device refuses a fixed exposure while auto exposure is on.
  EXPECT_EQ(camera->ControlWrites(),
            (std::vector<uint32_t>{V4L2_CID_EXPOSURE_AUTO, V4L2_CID_EXPOSURE_ABSOLUTE, V4L2_CID_GAIN}));
  const v4l2::ControlState* exposure = FindControl(source->Controls(), "exposure");
  ASSERT_NE(exposure, nullptr);
  EXPECT_TRUE(exposure->present);
  EXPECT_EQ(exposure->value, 300);
  EXPECT_EQ(exposure->minimum, 1);
  EXPECT_EQ(exposure->maximum, 5000);
  EXPECT_EQ(FindControl(source->Controls(), "gain")->value, 64);
}

TEST_F(V4l2DriverTest, AutoExposureAndOutOfRangeValues) {
  EmulatedV4l2Camera* camera = AddCamera();
  ASSERT_NE(camera, nullptr);
  V4l2SourceOptions options;
  options.controls.exposure = 300;
  auto manual = Open("/dev/video0", options);
  SourceConfig granted;
  ASSERT_TRUE(manual->Configure(SourceConfig{PixelFormat::kYuyv}, &granted).ok());
  manual->Stop();
  ASSERT_EQ(camera->Control(V4L2_CID_EXPOSURE_AUTO), V4L2_EXPOSURE_MANUAL);

  options.controls = {};
  options.controls.auto_exposure = true;
  auto automatic = Open("/dev/video0", options);
  ASSERT_TRUE(automatic->Configure(SourceConfig{PixelFormat::kYuyv}, &granted).ok());
  EXPECT_EQ(camera->Control(V4L2_CID_EXPOSURE_AUTO), V4L2_EXPOSURE_AUTO);
  automatic->Stop();

  options.controls = {};
  options.controls.gain = 999;
  auto too_much = Open("/dev/video0", options);
  auto result = too_much->Configure(SourceConfig{PixelFormat::kYuyv}, &granted);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(result.status().message().find("gain 999 is not in [0, 255]"), std::string::npos)
      << result.status().message();
  EXPECT_EQ(camera->Control(V4L2_CID_GAIN), 32);  // untouched

  options.controls = {};
  options.controls.exposure = 10;
  options.controls.auto_exposure = true;
  auto conflicting = Open("/dev/video0", options);
  EXPECT_EQ(conflicting->Configure(SourceConfig{PixelFormat::kYuyv}, &granted).status().code(),
            StatusCode::kInvalidArgument);
}

TEST_F(V4l2DriverTest, AbsentControlsAreReportedNotErrors) {
  EmulatedCameraOptions camera_options;
  camera_options.controls = false;
  ASSERT_NE(AddCamera(camera_options), nullptr);
  V4l2SourceOptions options;
  options.controls.exposure = 300;
  options.controls.gain = 10;
  auto source = Open("/dev/video0", options);
  ASSERT_NE(source, nullptr);
  SourceConfig granted;
  auto result = source->Configure(SourceConfig{PixelFormat::kYuyv}, &granted);
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  ASSERT_EQ(source->Controls().size(), 3u);
  const v4l2::ControlState* exposure = FindControl(source->Controls(), "exposure");
  ASSERT_NE(exposure, nullptr);
  EXPECT_FALSE(exposure->present);
  EXPECT_EQ(exposure->ToString(), "exposure: absent: exposure 300 not applied");
  EXPECT_FALSE(FindControl(source->Controls(), "gain")->present);
  EXPECT_TRUE(source->Next(milliseconds(2000)).ok());
}

}  // namespace
}  // namespace px

int main(int argc, char** argv) { return px::testing::RunTestsUnderUmockdev(argc, argv); }
