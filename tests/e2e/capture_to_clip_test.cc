// Simulated capture -> recording -> clip, through the same job the daemon runs, checked the
// way a player sees the result.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "capture/recording.h"
#include "device/clip_job.h"
#include "tests/e2e/e2e_shot.h"
#include "tests/testing/temp_dir.h"
#include "tests/testing/video_probe.h"

namespace px {
namespace {

class CaptureToClipTest : public ::testing::TestWithParam<PixelFormat> {};

TEST_P(CaptureToClipTest, ClipDecodesWithTheExpectedFramesSizeAndDuration) {
  // Half-size tiles (320x240) keep the test quick; geometry and code paths are the product's.
  auto shot = e2e::CaptureShot(e2e::Pop9Spec(0.5, GetParam()), "still_life");
  ASSERT_TRUE(shot.ok()) << shot.status().ToString();

  testing::TempDir dir;
  Recording recording;
  recording.source.model = "sim:e2e";
  recording.source.kind = FrameSetKind::kLatticeFrame;
  recording.source.rig = shot->rig;
  recording.frames = shot->capture;
  recording.created_by = "e2e test";
  ASSERT_TRUE(WriteRecording(dir.path() / "capture", recording).ok());

  device::ClipJobOptions options;
  options.pipeline.direct.duration_s = 1.2;
  options.pipeline.direct.fps = 15;
  const auto clip_path = dir.path() / "clips" / "shot.mp4";
  std::filesystem::create_directories(clip_path.parent_path());
  auto report = device::RunClipJob(dir.path() / "capture", clip_path, options);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_EQ(report->frames_written, 18);

  auto probe = testing::ProbeVideo(clip_path);
  ASSERT_TRUE(probe.ok()) << probe.status().ToString();
  EXPECT_EQ(probe->codec, "h264");
  EXPECT_EQ(probe->pixel_format, "yuv420p");
  EXPECT_EQ(probe->frames_decoded, 18);
  EXPECT_EQ(probe->width, 320);
  EXPECT_EQ(probe->height, 240);
  EXPECT_NEAR(probe->fps, 15.0, 1e-6);
  EXPECT_NEAR(probe->duration_s, 1.2, 1.0 / 15);
  EXPECT_TRUE(probe->moov_before_mdat) << "not faststart: browsers would wait for the whole file";
  // The dolly moves: the first and last frames differ, yet show the same scene.
  const double first_last_psnr = cv::PSNR(probe->first_frame, probe->last_frame);
  EXPECT_LT(first_last_psnr, 30.0);
  EXPECT_GT(first_last_psnr, 10.0);

  // The camera path and report sit beside the clip, and the raw capture is still whole.
  std::ifstream report_file(report->report_path);
  nlohmann::json report_json = nlohmann::json::parse(report_file, nullptr, false);
  ASSERT_FALSE(report_json.is_discarded());
  EXPECT_FALSE(report_json.dump().find("establishing_dolly") == std::string::npos) << report_json.dump();
  EXPECT_TRUE(ReadRecording(dir.path() / "capture").ok());
}

INSTANTIATE_TEST_SUITE_P(SensorFormats,
                         CaptureToClipTest,
                         ::testing::Values(PixelFormat::kRgb888, PixelFormat::kNv12, PixelFormat::kBayerRggb8),
                         [](const auto& param_info) { return std::string(PixelFormatName(param_info.param)); });

}  // namespace
}  // namespace px
