// Image sets and lattice frames through the whole pipeline, calibrated by structure from
// motion: a tethered hand-held set (intrinsics from a calibration, no poses) and a lattice frame
// with no rig calibration at all (lattice found blind).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "eval/calib/sim_image_set.h"
#include "eval/calib/sim_lattice_shot.h"
#include "pipeline/core/pixel_format.h"
#include "pipeline/run/pipeline.h"
#include "tests/testing/counting_frame_sink.h"

namespace px::sim_calib {
namespace {

using CountingSink = testing::CountingFrameSink;

// The hand-held set as a tethered camera delivers it (an image set, intrinsics from a
// calibration with one lens per image, no poses).
FrameSet CaptureOf(const ImageSet& set, RigCalibration* intrinsics) {
  FrameSet capture;
  capture.kind = FrameSetKind::kImageSet;
  capture.capture_id = 4;
  for (const calib::SfmImage& image : set.images) {
    Frame frame;
    frame.image = FromBgr(image.image, PixelFormat::kRgb888).value();
    capture.frames.push_back(std::move(frame));
    intrinsics->lenses.push_back(LensCalibration{});
    intrinsics->lenses.back().camera = set.camera;
  }
  return capture;
}

PipelineOptions FiveFrames() {
  PipelineOptions options;
  options.direct.fps = 5;
  options.direct.duration_s = 1;
  return options;
}

// Structure from motion, depth and a clip.
TEST(IncrementalSfmSimTest, ImageSetRunsThroughThePipeline) {
  const ImageSet set = HandHeld(/*known_focal=*/true);
  RigCalibration intrinsics;
  const FrameSet capture = CaptureOf(set, &intrinsics);
  PipelineOptions options = FiveFrames();
  CountingSink sink;
  StatusOr<PipelineReport> report = RunPipeline(capture, intrinsics, options, &sink);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  std::printf("pipeline: %s: %s\n", report->calibration.c_str(), report->calibration_summary.c_str());
  for (const std::string& warning : report->warnings) std::printf("  warning: %s\n", warning.c_str());
  EXPECT_EQ(report->calibration, "structure from motion");
  EXPECT_NE(report->calibration_summary.find("4 of 4 images registered"), std::string::npos);
  EXPECT_EQ(report->num_views, 4);
  EXPECT_EQ(sink.frames, 5);
  EXPECT_EQ(sink.size, cv::Size(640, 480));  // under image_set_max_side_px: as taken
  EXPECT_LT(report->mean_hole_ratio, 0.05);
}

// Photos larger than the working size are processed at it: the same set with a working size of
// 400 px is posed with its intrinsics scaled along, gets depth and a 3D move, and makes a
// 400x300 clip.
TEST(IncrementalSfmSimTest, LargePhotosAreProcessedAtTheWorkingSize) {
  const ImageSet set = HandHeld(/*known_focal=*/true);
  RigCalibration intrinsics;
  const FrameSet capture = CaptureOf(set, &intrinsics);
  PipelineOptions options = FiveFrames();
  options.image_set_max_side_px = 400;
  CountingSink sink;
  StatusOr<PipelineReport> report = RunPipeline(capture, intrinsics, options, &sink);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  std::printf("pipeline at 400 px: %s: %s; %s\n",
              report->calibration.c_str(),
              report->calibration_summary.c_str(),
              report->path.move.c_str());
  EXPECT_NE(report->calibration_summary.find("4 of 4 images registered"), std::string::npos);
  // The lenses' intrinsics scaled with the photos: still used as metadata, not self-calibrated.
  EXPECT_NE(report->calibration_summary.find("focal metadata"), std::string::npos) << report->calibration_summary;
  EXPECT_EQ(sink.frames, 5);
  EXPECT_EQ(sink.size, cv::Size(400, 300));
  EXPECT_EQ(report->path.kind, PathKind::kNovelView) << report->path.reason;
  EXPECT_LT(report->mean_hole_ratio, 0.05);
}

// A lattice frame with no rig calibration at all (no layout, no lens poses): the lattice is found
// blind, the tiles are posed by structure from motion (focal self-calibrated, reported
// unobservable on parallel lenses), the report says so, and a clip is still made.

TEST(IncrementalSfmSimTest, LatticeFrameWithoutRigCalibrationMakesAClip) {
  StatusOr<eval::LatticeShot> shot =
      eval::CaptureLatticeShot(eval::HalfSize(eval::RealisticSpec(SimCameraSpec::Pop9(), 0)), "still_life");
  ASSERT_TRUE(shot.ok()) << shot.status().ToString();
  FrameSet capture;
  capture.kind = FrameSetKind::kLatticeFrame;
  capture.capture_id = 5;
  Frame frame;
  frame.image = FromBgr(shot->sensor, PixelFormat::kRgb888).value();
  capture.frames.push_back(std::move(frame));
  PipelineOptions options = FiveFrames();
  // Fewer features and sweep steps than the defaults keep this under half a minute on 2 cores;
  // 320x240 tiles need no more.
  options.sfm.features.max_features = 1500;
  options.sfm.focal_sweep_steps = 8;
  CountingSink sink;
  StatusOr<PipelineReport> report = RunPipeline(capture, RigCalibration{}, options, &sink);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  std::printf("no rig calibration: %s: %s\n", report->calibration.c_str(), report->calibration_summary.c_str());
  for (const std::string& warning : report->warnings) std::printf("  warning: %s\n", warning.c_str());
  EXPECT_EQ(report->calibration, "structure from motion (no rig calibration)");
  EXPECT_EQ(report->num_views, 9);
  EXPECT_EQ(sink.frames, 5);
  const auto warned = [&](const std::string& text) {
    return std::any_of(report->warnings.begin(), report->warnings.end(), [&](const std::string& w) {
      return w.find(text) != std::string::npos;
    });
  };
  EXPECT_TRUE(warned("no factory rig calibration: lattice found blind (3x3"));
  EXPECT_TRUE(warned("focal length is unobservable"));
}

}  // namespace
}  // namespace px::sim_calib
