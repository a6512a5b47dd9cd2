#include "pipeline/run/pipeline.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <opencv2/imgproc.hpp>

#include "pipeline/render/plane_scene_testing.h"
#include "pipeline/run/image_set_scale.h"

namespace px {
namespace {

using render::testing::PlaneScene;

// A half-size Pop9: 3x3 lenses 25 mm apart, 320x240 tiles at f = 280 px, tiles rotated 180
// degrees on the sensor, seeing the analytic two-plane scene (foreground at 1 m, background at 3 m).
constexpr int kTileWidth = 320;
constexpr int kTileHeight = 240;
constexpr double kFocalPx = 280;
constexpr double kBaselineM = 0.025;

RigCalibration TestRig() {
  RigCalibration rig;
  rig.rig_name = "test-3x3";
  rig.lattice = LatticeLayout::Regular(3, 3, kTileWidth, kTileHeight, 8, TileOrientation::kRotated180);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      LensCalibration lens;
      lens.camera = CameraModel::Pinhole(kTileWidth, kTileHeight, kFocalPx);
      const Eigen::Vector3d centre((c - 1) * kBaselineM, (r - 1) * kBaselineM, 0);
      lens.cam_from_rig = Rigid3(Eigen::Quaterniond::Identity(), -centre);
      rig.lenses.push_back(lens);
    }
  }
  rig.nominal_depth_min_m = 0.5;
  rig.nominal_depth_max_m = 8.0;
  return rig;
}

// The sensor frame the rig would deliver: each lens's exact view, turned over into its tile.
cv::Mat SensorFrame(const RigCalibration& rig, const PlaneScene& scene) {
  cv::Mat sensor(rig.lattice.sensor_height, rig.lattice.sensor_width, CV_8UC3, cv::Scalar::all(0));
  for (int i = 0; i < rig.NumViews(); ++i) {
    cv::Mat image, depth;
    scene.Render(rig.lenses[i].camera, rig.lenses[i].cam_from_rig, &image, &depth);
    cv::rotate(image, sensor(rig.lattice.tiles[i].rect), cv::ROTATE_180);
  }
  return sensor;
}

FrameSet Capture(const cv::Mat& sensor) {
  FrameSet capture;
  capture.kind = FrameSetKind::kLatticeFrame;
  capture.capture_id = 7;
  Frame frame;
  frame.image = FromBgr(sensor, PixelFormat::kRgb888).value();
  frame.sequence = 3;
  capture.frames.push_back(std::move(frame));
  return capture;
}

class CollectingSink : public FrameSink {
 public:
  Status Consume(int index, const cv::Mat& bgr) override {
    indices.push_back(index);
    frames.push_back(bgr.clone());
    return OkStatus();
  }
  std::vector<int> indices;
  std::vector<cv::Mat> frames;
};

// PSNR over pixels more than 2 px from a depth discontinuity of the exact view: point sampling
// places silhouettes only to a pixel, so errors there measure sampling, not the pipeline.
double PsnrAwayFromSilhouettes(const cv::Mat& got, const cv::Mat& want, const cv::Mat& want_depth) {
  cv::Mat edges(want.size(), CV_8U, cv::Scalar(0));
  for (int y = 0; y + 1 < want.rows; ++y) {
    for (int x = 0; x + 1 < want.cols; ++x) {
      const float z = want_depth.at<float>(y, x);
      if (std::abs(want_depth.at<float>(y, x + 1) - z) > 0.1f * z ||
          std::abs(want_depth.at<float>(y + 1, x) - z) > 0.1f * z) {
        edges.at<uint8_t>(y, x) = 255;
      }
    }
  }
  cv::dilate(edges, edges, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(5, 5)));
  cv::Mat diff;
  cv::absdiff(got, want, diff);
  diff.convertTo(diff, CV_32F);
  cv::Mat squared = diff.mul(diff);
  squared.setTo(0, edges);
  const cv::Scalar sum = cv::sum(squared);
  const double mse = (sum[0] + sum[1] + sum[2]) / (3.0 * (edges.total() - cv::countNonZero(edges)));
  return mse <= 0 ? 99.0 : 10.0 * std::log10(255.0 * 255.0 / mse);
}

PipelineOptions ShortClip() {
  PipelineOptions options;
  options.direct.fps = 10;
  options.direct.duration_s = 1;  // 10 frames
  return options;
}

class PipelineTest : public ::testing::Test {
 protected:
  void SetUp() override { sensor_ = SensorFrame(rig_, scene_); }
  // Every third frame of a 10-frame clip against the exact render of its viewpoint (thresholds:
  // RendersTheDollyFromALatticeFrame).
  void ExpectFramesMatchTheExactRenders(const CameraPath& path, const CollectingSink& sink) const {
    ASSERT_EQ(sink.frames.size(), 10u);
    for (int i = 0; i < 10; i += 3) {
      const double t = path.FrameTime(i);
      cv::Mat want, want_depth;
      scene_.Render(path.CameraAt(t), path.PoseAt(t), &want, &want_depth);
      ASSERT_EQ(sink.frames[i].size(), want.size());
      EXPECT_GT(PsnrAwayFromSilhouettes(sink.frames[i], want, want_depth), 38.0) << "frame " << i;
      EXPECT_GT(cv::PSNR(sink.frames[i], want), 32.0) << "frame " << i;
    }
  }
  PlaneScene scene_;
  RigCalibration rig_ = TestRig();
  cv::Mat sensor_;
};

// An authored linear dolly across the middle row, converging on the background (the median
// depth), through the rig's own positions, so the frames can be held to the exact renders.
std::shared_ptr<const direct::Shot> MiddleRowShot() {
  auto shot = std::make_shared<direct::Shot>();
  direct::ShotSegment segment;
  segment.interpolation = direct::Interpolation::kLinear;
  for (double x : {-kBaselineM, kBaselineM}) {
    direct::ShotKeyframe key;
    key.t = x < 0 ? 0 : 1;
    key.position_m = Eigen::Vector3d(x, 0, 0);
    key.look_at_m = Eigen::Vector3d(0, 0, 3.0);
    key.focal_px = kFocalPx;
    segment.keyframes.push_back(key);
  }
  shot->segments.push_back(segment);
  return shot;
}

TEST_F(PipelineTest, RendersTheDollyFromALatticeFrame) {
  CollectingSink sink;
  std::map<std::string, std::vector<double>> progress;
  PipelineOptions options = ShortClip();
  options.shot = MiddleRowShot();
  StatusOr<PipelineReport> report =
      RunPipeline(Capture(sensor_), rig_, options, &sink, [&](const std::string& stage, double fraction) {
        progress[stage].push_back(fraction);
        return true;
      });
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_EQ(report->num_views, 9);
  EXPECT_TRUE(report->warnings.empty()) << report->warnings.front();
  // The views are exact: per-shot refinement confirms the factory calibration.
  EXPECT_EQ(report->calibration, "factory (confirmed by refinement)") << report->calibration_summary;
  EXPECT_EQ(report->frames_rendered, 10);
  // auto: the CPU here unless a GPU is found (render_backend.h).
  EXPECT_TRUE(report->render_backend == "cpu" || report->render_backend == "gl-egl") << report->render_backend;
  EXPECT_FALSE(report->render_backend_reason.empty());
  ASSERT_EQ(sink.indices.size(), 10u);
  for (int i = 0; i < 10; ++i) EXPECT_EQ(sink.indices[i], i);

  std::vector<std::string> stages;
  for (const StageTiming& timing : report->timings) {
    stages.push_back(timing.stage);
    EXPECT_GE(timing.ms, 0) << timing.stage;
  }
  EXPECT_EQ(stages, (std::vector<std::string>{"lattice", "calib", "depth", "direct", "render", "encode"}));
  for (const char* stage : {"lattice", "depth", "direct", "render"}) EXPECT_FALSE(progress[stage].empty()) << stage;
  EXPECT_EQ(progress["render"].back(), 1.0);

  // The authored dolly across the middle row.
  const CameraPath& path = report->path;
  EXPECT_EQ(path.kind, PathKind::kNovelView);
  EXPECT_LT((CameraCentre(path.PoseAt(0)) - Eigen::Vector3d(-kBaselineM, 0, 0)).norm(), 1e-9);
  EXPECT_LT((CameraCentre(path.PoseAt(1)) - Eigen::Vector3d(kBaselineM, 0, 0)).norm(), 1e-9);
  EXPECT_EQ(path.width, kTileWidth);
  EXPECT_EQ(path.height, kTileHeight);

  // Every third frame against the exact render of its viewpoint. Depth is estimated now (about
  // 1 % error on this scene), but on the dolly the target is never more than 12.5 mm from a lens,
  // where 1 % of depth moves texture by a few hundredths of a pixel; what remains is bilinear
  // resampling of ~15 px texture periods (about 45 dB) and silhouettes a pixel off. Measured
  // 42-45 dB away from silhouettes and 37-43 dB whole, while the same frames compared with the
  // views mirrored along the dolly (17-50 mm away) score 24-30 dB.
  ExpectFramesMatchTheExactRenders(path, sink);
  // The dolly stays within the rig: hardly anything to inpaint.
  EXPECT_LT(report->mean_hole_ratio, 0.01);
  // Per-frame coverage (before hole filling), one report per frame at the output size.
  ASSERT_EQ(report->frame_coverage.size(), static_cast<size_t>(report->frames_rendered));
  for (const CoverageReport& frame : report->frame_coverage) {
    EXPECT_EQ(frame.width, path.width);
    EXPECT_LT(frame.hole_ratio, 0.05);
    EXPECT_LT(frame.hole_score, 2.0);  // a valid viewpoint by the paper's rule
  }
}

// A boomerang plays the move and then the same frames backwards, each place drawn once; a hold
// repeats the last frame without drawing it again.
TEST_F(PipelineTest, ABoomerangShowsItsFramesBackwardsAndDrawsEachPlaceOnce) {
  CollectingSink sink;
  PipelineOptions options = ShortClip();
  options.shot = MiddleRowShot();
  options.direct.timing = {ClipStyle::kBoomerang, ClipEase::kSmooth, 0};
  StatusOr<PipelineReport> report = RunPipeline(Capture(sensor_), rig_, options, &sink);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  ASSERT_EQ(report->frames_rendered, 19);
  EXPECT_EQ(report->frames_reused, 9);
  ASSERT_EQ(sink.frames.size(), 19u);
  ASSERT_EQ(report->frame_coverage.size(), 19u);
  for (int i = 0; i < 9; ++i) {
    EXPECT_EQ(cv::norm(sink.frames[i], sink.frames[18 - i], cv::NORM_INF), 0.0) << "frame " << i;
  }
  EXPECT_GT(cv::norm(sink.frames[0], sink.frames[9], cv::NORM_L1), 0.0) << "the move must move";
  // Eased: the first step is a small fraction of the middle one.
  const CameraPath& path = report->path;
  EXPECT_LT(path.FrameTime(1) - path.FrameTime(0), 0.25 * (path.FrameTime(5) - path.FrameTime(4)));

  CollectingSink held;
  options.direct.timing = {ClipStyle::kOnce, ClipEase::kSmooth, 0.5};
  report = RunPipeline(Capture(sensor_), rig_, options, &held);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  ASSERT_EQ(report->frames_rendered, 15);
  EXPECT_EQ(report->frames_reused, 5);
  for (int i = 10; i < 15; ++i) EXPECT_EQ(cv::norm(held.frames[i], held.frames[9], cv::NORM_INF), 0.0);
}

// A portrait clip from a landscape capture: the frames have the asked size and show what the
// exact render of their (re-framed) viewpoints shows; a larger frame says it is upsampled.
TEST_F(PipelineTest, ThePathIsFramedForTheOutputsSizeAndAspect) {
  CollectingSink sink;
  PipelineOptions options = ShortClip();
  options.shot = MiddleRowShot();
  options.direct.output.aspect = 9.0 / 16.0;  // at the capture's height: 136x240 from 320x240
  StatusOr<PipelineReport> report = RunPipeline(Capture(sensor_), rig_, options, &sink);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  const CameraPath& path = report->path;
  EXPECT_EQ(path.width, 136);
  EXPECT_EQ(path.height, 240);
  EXPECT_DOUBLE_EQ(path.output_scale, 1.0);
  ASSERT_EQ(sink.frames.size(), 10u);
  for (int i : {0, 5, 9}) {
    ASSERT_EQ(sink.frames[i].size(), cv::Size(136, 240));
    cv::Mat want, want_depth;
    scene_.Render(path.CameraAt(path.FrameTime(i)), path.PoseAt(path.FrameTime(i)), &want, &want_depth);
    EXPECT_GT(PsnrAwayFromSilhouettes(sink.frames[i], want, want_depth), 36.0) << "frame " << i;
  }
  EXPECT_TRUE(report->warnings.empty()) << report->warnings.front();

  CollectingSink large;
  options.direct.output = {640, 480, 0};
  auto doubled = std::make_shared<direct::Shot>(*MiddleRowShot());  // focal_px is in output pixels
  for (direct::ShotKeyframe& key : doubled->segments[0].keyframes) key.focal_px = 2 * *key.focal_px;
  options.shot = doubled;
  report = RunPipeline(Capture(sensor_), rig_, options, &large);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_DOUBLE_EQ(report->path.output_scale, 2.0);
  ASSERT_EQ(large.frames.front().size(), cv::Size(640, 480));
  bool said = false;
  for (const std::string& warning : report->warnings) said |= warning.find("upsampled 2.00x") != std::string::npos;
  EXPECT_TRUE(said) << "the report must say the clip is upsampled";
}

// Without a shot the taxonomy decides: no faces (no detector here), so an establishing move
// (row 0 of table 1) through viewpoints the renderer covers.
TEST_F(PipelineTest, ChoosesAnEstablishingMoveThroughValidViewpoints) {
  CollectingSink sink;
  StatusOr<PipelineReport> report = RunPipeline(Capture(sensor_), rig_, ShortClip(), &sink);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_EQ(report->path.kind, PathKind::kNovelView);
  EXPECT_TRUE(report->path.move == "establishing_dolly" || report->path.move == "establishing_dolly_out")
      << report->path.move;
  EXPECT_FALSE(report->direction.fell_back) << report->path.reason;
  EXPECT_LT(report->direction.plan.max_hole_score, 2.0);
  EXPECT_GT(report->direction.coverage_probes, 0);
  EXPECT_EQ(report->frames_rendered, 10);
  EXPECT_LT(report->mean_hole_ratio, 0.01);
}

// The same dolly drawn by the GL back end on OSMesa (llvmpipe, on every machine this builds on),
// held to the same exact renders as the CPU's frames above; and with the OSMesa library missing,
// drawn by the CPU with the library named in the report.
TEST_F(PipelineTest, RendersOnGlOrFallsBackToTheCpuWithTheReason) {
  for (const bool missing : {false, true}) {
    SCOPED_TRACE(missing ? "libOSMesa missing" : "osmesa");
    CollectingSink sink;
    PipelineOptions options = ShortClip();
    options.shot = MiddleRowShot();
    options.render_backend.backend = render::gl::RenderBackend::kOsmesa;
    if (missing) options.render_backend.context.osmesa_library = "libOSMesa-not-here.so.8";
    StatusOr<PipelineReport> report = RunPipeline(Capture(sensor_), rig_, options, &sink);
    ASSERT_TRUE(report.ok()) << report.status().ToString();
    EXPECT_EQ(report->frames_rendered, 10);
    if (missing) {
      EXPECT_EQ(report->render_backend, "cpu");
      EXPECT_NE(report->render_backend_reason.find("cpu: GL failed"), std::string::npos)
          << report->render_backend_reason;
      EXPECT_NE(report->render_backend_reason.find("libOSMesa-not-here.so.8"), std::string::npos)
          << report->render_backend_reason;
    } else {
      EXPECT_EQ(report->render_backend, "gl-osmesa");
      EXPECT_NE(report->render_backend_reason.find("gl-osmesa: asked for"), std::string::npos)
          << report->render_backend_reason;
    }
    // No frame fell back; a forced back end that could not start is a warning.
    ASSERT_EQ(report->warnings.size(), missing ? 1u : 0u) << ::testing::PrintToString(report->warnings);
    if (missing) {
      EXPECT_NE(report->warnings[0].find("asked for osmesa, drawn by the cpu"), std::string::npos);
    }
    ExpectFramesMatchTheExactRenders(report->path, sink);
    EXPECT_LT(report->mean_hole_ratio, 0.01);
  }
}

TEST_F(PipelineTest, CancelsWhenProgressSaysSo) {
  CollectingSink sink;
  StatusOr<PipelineReport> report =
      RunPipeline(Capture(sensor_), rig_, ShortClip(), &sink, [](const std::string& stage, double fraction) {
        return !(stage == "render" && fraction >= 0.3);
      });
  EXPECT_EQ(report.status().code(), StatusCode::kCancelled);
  EXPECT_NE(report.status().message().find("render"), std::string::npos);
  EXPECT_EQ(sink.frames.size(), 3u);  // stopped after the frame that reached 30 %
}

TEST_F(PipelineTest, UnusableLatticeFrameIsNamed) {
  FrameSet capture = Capture(sensor_);
  capture.frames[0].status = FrameStatus::kCorrupt;
  capture.frames[0].status_detail = "short read: 1000 of 602112 bytes";
  CollectingSink sink;
  const Status status = RunPipeline(capture, rig_, ShortClip(), &sink).status();
  EXPECT_EQ(status.code(), StatusCode::kDataLoss);
  EXPECT_NE(status.message().find("capture 7 frame 0 (sequence 3) is corrupt: short read"), std::string::npos)
      << status.message();
  EXPECT_TRUE(sink.frames.empty());

  capture.frames[0].status = FrameStatus::kDropped;
  EXPECT_EQ(RunPipeline(capture, rig_, ShortClip(), &sink).status().code(), StatusCode::kUnavailable);
}

TEST_F(PipelineTest, SkipsBadFramesAndBlankLenses) {
  FrameSet capture = Capture(sensor_);
  // A dropped frame ahead of the good one, and lens 4 covered (its tile flat grey).
  Frame dropped;
  dropped.status = FrameStatus::kDropped;
  dropped.sequence = 2;
  capture.frames.insert(capture.frames.begin(), dropped);
  cv::Mat covered = sensor_.clone();
  covered(rig_.lattice.tiles[4].rect).setTo(cv::Scalar::all(60));
  capture.frames[1].image = FromBgr(covered, PixelFormat::kRgb888).value();

  std::vector<std::string> warnings;
  StatusOr<std::vector<View>> views = MakeViewsFromCapture(capture, rig_, &warnings);
  ASSERT_TRUE(views.ok()) << views.status().ToString();
  ASSERT_EQ(views->size(), 8u);
  for (const View& view : *views) EXPECT_NE(view.id.value, 4);
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_NE(warnings[0].find("frame 0 (sequence 2) skipped"), std::string::npos) << warnings[0];
  EXPECT_NE(warnings[1].find("view 4 is blank"), std::string::npos) << warnings[1];
  // Views are upright and calibrated: view 0 is the top-left lens's exact image.
  cv::Mat want, want_depth;
  scene_.Render(rig_.lenses[0].camera, rig_.lenses[0].cam_from_rig, &want, &want_depth);
  EXPECT_EQ(cv::norm((*views)[0].image, want, cv::NORM_INF), 0.0);
}

TEST_F(PipelineTest, ALatticeThatMovedIsCutWhereItIsNow) {
  // The whole lattice 3 px right and 2 px down of where the rig calibration puts it (a knock).
  RigCalibration moved_rig = rig_;
  for (Tile& tile : moved_rig.lattice.tiles) tile.rect += cv::Point(3, 2);
  const cv::Mat moved = SensorFrame(moved_rig, scene_);
  std::vector<std::string> warnings;
  StatusOr<std::vector<View>> views = MakeViewsFromCapture(Capture(moved), rig_, &warnings);
  ASSERT_TRUE(views.ok()) << views.status().ToString();
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("lattice moved: tiles found up to 3.6 px"), std::string::npos) << warnings[0];
  cv::Mat want, want_depth;
  scene_.Render(rig_.lenses[4].camera, rig_.lenses[4].cam_from_rig, &want, &want_depth);
  EXPECT_EQ(cv::norm((*views)[4].image, want, cv::NORM_INF), 0.0);
}

TEST_F(PipelineTest, TruncatedFrameGivesTheViewsThatArrivedWhole) {
  FrameSet capture = Capture(sensor_);
  // A short transfer: the buffer stops inside the third row of tiles (as a camera's DMA would).
  const LatticeLayout& lattice = rig_.lattice;
  const int cut_row = lattice.tiles[6].rect.y + 10;
  std::vector<uint8_t>& bytes = capture.frames[0].image.bytes;
  bytes.resize(static_cast<size_t>(cut_row) * lattice.sensor_width * 3 + 5);
  capture.frames[0].status = FrameStatus::kCorrupt;
  capture.frames[0].status_detail = "truncated";

  std::vector<std::string> warnings;
  StatusOr<std::vector<View>> views = MakeViewsFromCapture(capture, rig_, &warnings);
  ASSERT_TRUE(views.ok()) << views.status().ToString();
  ASSERT_EQ(views->size(), 6u);
  for (const View& view : *views) EXPECT_LT(view.id.value, 6);
  ASSERT_EQ(warnings.size(), 4u);
  EXPECT_NE(warnings[0].find("is truncated"), std::string::npos) << warnings[0];
  EXPECT_NE(warnings[0].find("using the views in its first " + std::to_string(cut_row) + " rows"), std::string::npos)
      << warnings[0];
  EXPECT_NE(warnings[1].find("view 6 was lost"), std::string::npos) << warnings[1];
  // The views that arrived are exact.
  cv::Mat want, want_depth;
  scene_.Render(rig_.lenses[3].camera, rig_.lenses[3].cam_from_rig, &want, &want_depth);
  EXPECT_EQ(cv::norm((*views)[3].image, want, cv::NORM_INF), 0.0);

  // The whole pipeline makes a clip from them.
  CollectingSink sink;
  StatusOr<PipelineReport> report = RunPipeline(capture, rig_, ShortClip(), &sink);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_EQ(report->num_views, 6);
  EXPECT_EQ(sink.frames.size(), 10u);

  // Cut inside the first row of tiles: not two views left, and the error says why.
  bytes.resize(static_cast<size_t>(lattice.tiles[0].rect.y + 5) * lattice.sensor_width * 3);
  const Status status = RunPipeline(capture, rig_, ShortClip(), &sink).status();
  EXPECT_EQ(status.code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(status.message().find("only 0 of 9 views show the scene; view 0 was lost"), std::string::npos)
      << status.message();
}

TEST_F(PipelineTest, FrameInAnotherPixelFormatIsUsedAsItDecodes) {
  FrameSet capture = Capture(sensor_);
  capture.frames[0].image = FromBgr(sensor_, PixelFormat::kNv12).value();
  capture.frames[0].status = FrameStatus::kWrongFormat;
  capture.frames[0].status_detail = "got NV12, want RGB888";
  std::vector<std::string> warnings;
  StatusOr<std::vector<View>> views = MakeViewsFromCapture(capture, rig_, &warnings);
  ASSERT_TRUE(views.ok()) << views.status().ToString();
  EXPECT_EQ(views->size(), 9u);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("came as NV12, not as configured"), std::string::npos) << warnings[0];
  // A frame of the wrong size cannot be split by this rig's lattice.
  cv::Mat small;
  cv::resize(sensor_, small, cv::Size(), 0.5, 0.5);
  capture.frames[0].image = FromBgr(small, PixelFormat::kRgb888).value();
  EXPECT_EQ(MakeViewsFromCapture(capture, rig_, &warnings).status().code(), StatusCode::kInvalidArgument);
}

// The four corner lenses' images as a hand-held set, intrinsics from a rig with one lens per
// image (poses unknown to the pipeline). The scene's periodic textures fool feature matching,
// so image sets that succeed are tested on simulated scenes in eval/calib (eval/sfm_pipeline_test).
class ImageSetTest : public PipelineTest {
 protected:
  static constexpr int kCorners[4] = {0, 2, 6, 8};
  FrameSet ImageSet(bool same_place = false) const {
    FrameSet capture;
    capture.kind = FrameSetKind::kImageSet;
    capture.capture_id = 9;
    for (int i = 0; i < 4; ++i) {
      const LensCalibration& lens = rig_.lenses[same_place ? 0 : kCorners[i]];
      cv::Mat image, depth;
      scene_.Render(lens.camera, lens.cam_from_rig, &image, &depth);
      Frame frame;
      frame.image = FromBgr(image, PixelFormat::kRgb888).value();
      frame.sequence = static_cast<uint64_t>(i);
      capture.frames.push_back(std::move(frame));
    }
    return capture;
  }
  RigCalibration Intrinsics() const {
    RigCalibration rig;
    for (int i : kCorners) rig.lenses.push_back(rig_.lenses[i]);
    return rig;
  }
};

TEST_F(ImageSetTest, ASetWithoutParallaxFallsBackWithTheReason) {
  CollectingSink sink;
  StatusOr<PipelineReport> report = RunPipeline(ImageSet(/*same_place=*/true), Intrinsics(), ShortClip(), &sink);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  // No 3D: a morph or a flat pan and zoom, never a failed button.
  EXPECT_NE(report->path.kind, PathKind::kNovelView);
  EXPECT_EQ(sink.frames.size(), 10u);
  EXPECT_TRUE(std::any_of(report->warnings.begin(), report->warnings.end(), [](const std::string& w) {
    return w.find("capture 9: structure from motion failed") != std::string::npos;
  })) << ::testing::PrintToString(report->warnings);
}

// Hand-held photos larger than the working size are scaled to it, their focal length from EXIF
// and a lens calibrated at full size with them; frames that are not OK, smaller photos and
// lattice frames are left as they are.
TEST(ImageSetScaleTest, ScalesLargePhotosWithTheirFocalLengthAndLens) {
  FrameSet capture;
  capture.kind = FrameSetKind::kImageSet;
  RigCalibration rig;
  for (const cv::Size size : {cv::Size(2400, 1600), cv::Size(800, 600), cv::Size(2400, 1600)}) {
    Frame frame;
    frame.image = FromBgr(cv::Mat(size, CV_8UC3, cv::Scalar(10, 120, 230)), PixelFormat::kRgb888).value();
    frame.focal_length_px = 2000;
    capture.frames.push_back(std::move(frame));
    rig.lenses.push_back(LensCalibration{});
    rig.lenses.back().camera = CameraModel::Pinhole(size.width, size.height, 2000);
  }
  capture.frames[2].status = FrameStatus::kCorrupt;
  const std::optional<WorkingImageSet> working = ImageSetAtWorkingSize(1200, capture, rig);
  ASSERT_TRUE(working.has_value());
  EXPECT_NE(working->note.find("1 of 3 photos scaled to a longer side of 1200 px"), std::string::npos) << working->note;
  const std::vector<Frame>& frames = working->capture.frames;
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[0].image.width, 1200);
  EXPECT_EQ(frames[0].image.height, 800);
  EXPECT_DOUBLE_EQ(frames[0].focal_length_px, 1000);
  EXPECT_EQ(working->rig.lenses[0].camera.width, 1200);
  EXPECT_DOUBLE_EQ(working->rig.lenses[0].camera.fx, 1000);
  const cv::Mat scaled = ToBgr(frames[0].image).value();
  EXPECT_EQ(scaled.at<cv::Vec3b>(400, 600), cv::Vec3b(10, 120, 230));
  EXPECT_EQ(frames[1].image.width, 800);   // under the working size
  EXPECT_EQ(frames[2].image.width, 2400);  // corrupt: left for the stages to report
  EXPECT_EQ(frames[2].status, FrameStatus::kCorrupt);
  EXPECT_FALSE(ImageSetAtWorkingSize(0, capture, rig).has_value());
  EXPECT_FALSE(ImageSetAtWorkingSize(2400, capture, rig).has_value());  // nothing larger
  FrameSet lattice = capture;
  lattice.kind = FrameSetKind::kLatticeFrame;
  lattice.frames[2].status = FrameStatus::kOk;
  EXPECT_FALSE(ImageSetAtWorkingSize(1200, lattice, rig).has_value());
}

TEST_F(PipelineTest, RejectsWhatItCannotDo) {
  CollectingSink sink;
  FrameSet image_set = Capture(sensor_);
  image_set.kind = FrameSetKind::kImageSet;
  // One image cannot be calibrated: never fail the button, pan and zoom over it, and say why.
  StatusOr<PipelineReport> hand_held = RunPipeline(image_set, rig_, ShortClip(), &sink);
  ASSERT_TRUE(hand_held.ok()) << hand_held.status().ToString();
  EXPECT_EQ(hand_held->path.kind, PathKind::kPanZoom2d);
  EXPECT_EQ(hand_held->frames_rendered, 10);
  EXPECT_TRUE(std::any_of(hand_held->warnings.begin(), hand_held->warnings.end(), [](const std::string& w) {
    return w.find("an image set needs at least 2 images, got 1") != std::string::npos;
  })) << ::testing::PrintToString(hand_held->warnings);

  EXPECT_EQ(RunPipeline(Capture(sensor_), rig_, ShortClip(), nullptr).status().code(), StatusCode::kInvalidArgument);

  PipelineOptions options = ShortClip();
  options.render.aperture_samples = 0;
  EXPECT_NE(RunPipeline(Capture(sensor_), rig_, options, &sink).status().message().find("render.aperture_samples"),
            std::string::npos);
}

// Lens intrinsics but no lattice layout: the lattice is found blind and the tiles are posed by
// structure from motion with the lenses' intrinsics as metadata; the report says so.
TEST_F(PipelineTest, LatticeWithoutLayoutIsFoundBlindAndPosedBySfm) {
  CollectingSink sink;
  RigCalibration no_lattice = rig_;
  no_lattice.lattice = LatticeLayout();
  StatusOr<PipelineReport> report = RunPipeline(Capture(sensor_), no_lattice, ShortClip(), &sink);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_EQ(report->calibration, "structure from motion (no rig calibration)");
  EXPECT_EQ(report->num_views, 9);
  EXPECT_EQ(sink.frames.size(), 10u);
  EXPECT_TRUE(std::any_of(report->warnings.begin(), report->warnings.end(), [](const std::string& w) {
    return w.find("lens intrinsics of 9 of 9 tiles from the rig calibration") != std::string::npos;
  })) << ::testing::PrintToString(report->warnings);
}

}  // namespace
}  // namespace px
