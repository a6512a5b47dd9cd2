// The hand-held path's focal length from EXIF, end to end: a tethered camera (the simulated PTP
// camera) serves JPEGs of the simulated hand-held set with or without EXIF; the source reads the
// focal length from the JPEG, a recording carries it, and structure from motion uses it (or,
// without it, self-calibrates).
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>

#include "capture/recording.h"
#include "eval/calib/sim_image_set.h"
#include "pipeline/run/capture_calibration.h"
#include "sim/synthetic/exif_jpeg.h"
#include "tests/drivers/ptp_test_util.h"
#include "tests/testing/temp_dir.h"

namespace px::sim_calib {
namespace {

// The hand-held set as a tethered camera takes it, replayed from a recording of the capture.
FrameSet CaptureAndReplay(const ImageSet& set, bool with_exif) {
  ptp::testing::ResponderOptions camera;
  camera.image_width = set.camera.width;
  camera.image_height = set.camera.height;
  for (const calib::SfmImage& image : set.images) {
    std::vector<uint8_t> jpeg;
    EXPECT_TRUE(cv::imencode(".jpg", image.image, jpeg, {cv::IMWRITE_JPEG_QUALITY, 95}));
    camera.jpegs.push_back(
        with_exif ? px::sim::WithExifFocalLength(jpeg, set.camera.fx, set.camera.width, set.camera.height) : jpeg);
  }
  auto responder = std::make_shared<ptp::testing::PtpResponder>(camera);
  StatusOr<std::unique_ptr<FrameSource>> source = MakePtpSource(ptp::testing::ResponderSourceOptions(responder));
  EXPECT_TRUE(source.ok()) << source.status().ToString();
  if (!source.ok()) return {};
  SourceConfig wanted, granted;
  wanted.pixel_format = PixelFormat::kRgb888;
  wanted.shots = static_cast<int>(set.images.size());
  EXPECT_TRUE((*source)->Configure(wanted, &granted).ok());
  StatusOr<FrameSet> captured = (*source)->Next(std::chrono::milliseconds(20000));
  EXPECT_TRUE(captured.ok()) << captured.status().ToString();
  if (!captured.ok()) return {};
  for (const Frame& frame : captured->frames) {
    EXPECT_NEAR(frame.focal_length_px, with_exif ? set.camera.fx : 0.0, 0.01);
  }

  px::testing::TempDir temp;
  Recording recording;
  recording.source = (*source)->Describe();
  recording.frames = *captured;
  recording.created_by = "exif_focal_test";
  EXPECT_TRUE(WriteRecording(temp.path() / "shot", recording).ok());
  StatusOr<Recording> replayed = ReadRecording(temp.path() / "shot");
  EXPECT_TRUE(replayed.ok()) << replayed.status().ToString();
  if (!replayed.ok()) return {};
  for (size_t i = 0; i < replayed->frames.frames.size(); ++i) {
    EXPECT_EQ(replayed->frames.frames[i].focal_length_px, captured->frames[i].focal_length_px);
    EXPECT_EQ(replayed->frames.frames[i].focal_length_source, captured->frames[i].focal_length_source);
  }
  return replayed->frames;
}

StatusOr<CalibratedViews> Calibrate(const FrameSet& capture, std::vector<std::string>* warnings) {
  calib::SfmOptions sfm;
  sfm.focal_sweep_steps = 8;  // enough for the self-calibrated run; faster under load
  std::vector<StageTiming> timings;
  return CalibrateCapture(
      capture, RigCalibration{}, CalibOptions(), calib::RigRefinementOptions(), sfm, warnings, &timings);
}

TEST(ExifFocalTest, ATetheredSetWithExifReachesStructureFromMotionWithItsFocalLength) {
  const ImageSet set = HandHeld(/*known_focal=*/false);
  const FrameSet capture = CaptureAndReplay(set, /*with_exif=*/true);
  ASSERT_EQ(capture.frames.size(), set.images.size());
  EXPECT_EQ(capture.frames[0].focal_length_source, "EXIF focal length and focal plane resolution");
  std::vector<std::string> warnings;
  StatusOr<CalibratedViews> views = Calibrate(capture, &warnings);
  ASSERT_TRUE(views.ok()) << views.status().ToString();
  std::printf("with EXIF: %s\n", views->summary.c_str());
  EXPECT_NE(views->summary.find("focal metadata"), std::string::npos) << views->summary;
  EXPECT_NE(views->summary.find("focal length of 4 of 4 images from their metadata (EXIF"), std::string::npos)
      << views->summary;
  ASSERT_EQ(views->views.size(), 4u);
  for (const View& view : views->views) EXPECT_NEAR(view.camera.fx, set.camera.fx, 0.01 * set.camera.fx);
}

TEST(ExifFocalTest, ATetheredSetWithoutExifIsSelfCalibrated) {
  const ImageSet set = HandHeld(/*known_focal=*/false);
  const FrameSet capture = CaptureAndReplay(set, /*with_exif=*/false);
  ASSERT_EQ(capture.frames.size(), set.images.size());
  std::vector<std::string> warnings;
  StatusOr<CalibratedViews> views = Calibrate(capture, &warnings);
  ASSERT_TRUE(views.ok()) << views.status().ToString();
  std::printf("without EXIF: %s\n", views->summary.c_str());
  EXPECT_NE(views->summary.find("focal self-calibrated"), std::string::npos) << views->summary;
  EXPECT_EQ(views->summary.find("from their metadata"), std::string::npos) << views->summary;
  ASSERT_EQ(views->views.size(), 4u);
}

}  // namespace
}  // namespace px::sim_calib
