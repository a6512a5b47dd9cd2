#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/imgproc.hpp>

#include "eval/real/contact_sheet.h"
#include "eval/real/leave_one_out.h"
#include "eval/real/path_eval.h"
#include "eval/real/path_measures.h"
#include "eval/real/real_set.h"
#include "pipeline/core/pixel_format.h"
#include "sim/synthetic/data_paths.h"
#include "sim/synthetic/ray_caster.h"
#include "sim/synthetic/scene_json.h"

namespace px::eval {
namespace {

namespace fs = std::filesystem;

TEST(RealSetTest, SmallSetsHoldOutEveryViewLargeOnesEveryEighth) {
  EXPECT_EQ(HeldOutViews(4), (std::vector<int>{0, 1, 2, 3}));
  EXPECT_EQ(HeldOutViews(9).size(), 9u);
  EXPECT_EQ(HeldOutViews(20), (std::vector<int>{0, 8, 16}));
  EXPECT_EQ(HeldOutViews(34), (std::vector<int>{0, 8, 16, 24, 32}));
}

TEST(RealSetTest, AMissingSetIsNamed) {
  const StatusOr<RealSet> set = LoadRealSet("/nonexistent/set", "x");
  ASSERT_FALSE(set.ok());
  EXPECT_NE(set.status().message().find("/nonexistent/set"), std::string::npos);
}

TEST(RealSetTest, AFolderOfTwoAnimationsIsReadAsParallaxClipReadsIt) {
  // The photo booth's folder holds the rectified and the raw wigglegram of one shot: one capture
  // of four views, not eight views of one scene.
  const fs::path dir = sim::SharedDataDir() / "multicam" / "photobooth_pi_4cam_person";
  if (!fs::exists(dir)) GTEST_SKIP() << dir.string() << " is absent (the shared real data sits beside the project)";
  StatusOr<RealSet> set = LoadRealSet(dir, "multicam/photobooth_pi_4cam_person");
  ASSERT_TRUE(set.ok()) << set.status().ToString();
  EXPECT_EQ(set->capture.frames.size(), 4u);
  EXPECT_EQ(set->held_out.size(), 4u);
}

TEST(ContactSheetTest, TilesCellsRowByRowWithLabels) {
  const cv::Mat red(100, 200, CV_8UC3, cv::Scalar(0, 0, 255));
  const cv::Mat grey(50, 100, CV_8U, cv::Scalar(128));
  const cv::Mat sheet = ContactSheet({{red, "a"}, {grey, "b"}, {red, "c"}}, 2, 100);
  ASSERT_FALSE(sheet.empty());
  // Two columns of 100 px, two rows of 50 px cells with their label strips.
  EXPECT_EQ(sheet.cols, 4 + 2 * 104);
  EXPECT_GT(sheet.rows, 2 * 50);
  EXPECT_EQ(sheet.at<cv::Vec3b>(10, 10), cv::Vec3b(0, 0, 255));       // the first cell
  EXPECT_EQ(sheet.at<cv::Vec3b>(10, 118), cv::Vec3b(128, 128, 128));  // the second, grey made BGR
  EXPECT_TRUE(ContactSheet({}, 2, 100).empty());
}

// A frame of a grey wall 2 m away in a camera at the origin, with a 2 px slit at columns 50-51
// that renders white and 4 m away; one source beside the camera (its image the grey wall) whose
// depth is `source_depth`.
struct SlitFixture {
  VirtualCamera camera;
  FrameRender frame;
  std::vector<View> views;
  std::vector<DepthMap> depth;

  explicit SlitFixture(const cv::Mat& source_depth) {
    camera.camera = CameraModel::Pinhole(100, 80, 100);
    frame.bgr = cv::Mat(80, 100, CV_8UC3, cv::Scalar(90, 90, 90));
    frame.depth_m = cv::Mat(80, 100, CV_32F, cv::Scalar(2.0f));
    frame.depth_m.colRange(50, 52).setTo(4.0f);
    View source;
    source.id.value = 0;
    source.camera = camera.camera;
    source.cam_from_world = Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-0.01, 0, 0));
    source.image = frame.bgr.clone();
    frame.bgr.colRange(50, 52).setTo(cv::Scalar(250, 250, 250));
    views.push_back(source);
    DepthMap map;
    map.id = source.id;
    map.depth_m = source_depth;
    depth.push_back(map);
    frame.sources = {source.id};
  }
};

TEST(ContactSheetTest, FileNamesOfSetsGivenByRelativePathAreNotHidden) {
  EXPECT_EQ(SafeFileName("../shared/data/handheld/office"), "shared_data_handheld_office");
  EXPECT_EQ(SafeFileName("lattice_frames/scan.jpg"), "lattice_frames_scan.jpg");
  EXPECT_EQ(SafeFileName("../.."), "set");
}

TEST(PathMeasuresTest, AGapTheSourcesDoNotShowIsTorn) {
  SlitFixture fixture(cv::Mat(80, 100, CV_32F, cv::Scalar(2.0f)));  // the source sees the wall unbroken
  cv::Mat map;
  const double torn = TornFraction(fixture.frame, fixture.camera, fixture.views, fixture.depth, {}, &map);
  EXPECT_NEAR(torn, 2.0 * 80 / (100 * 80), 0.005);
  EXPECT_EQ(map.at<uint8_t>(40, 50), 255);
  EXPECT_EQ(map.at<uint8_t>(40, 20), 0);
}

TEST(PathMeasuresTest, AGapTheSourcesSeeThroughIsNotTorn) {
  // The source sees the far surface through the slit too (the slit is real): 2 m wall, the slit at
  // the columns the slit's middle projects to in the source (0.01 m left at 2 m: half a pixel).
  cv::Mat source_depth(80, 100, CV_32F, cv::Scalar(2.0f));
  source_depth.colRange(49, 53).setTo(4.0f);
  SlitFixture fixture(source_depth);
  EXPECT_EQ(TornFraction(fixture.frame, fixture.camera, fixture.views, fixture.depth), 0.0);
}

TEST(PathMeasuresTest, AGapTheSourcesImagesShowIsNotTornWhateverTheirDepthSays) {
  // The source's depth smooths over the slit, but its image shows the slit's white there.
  SlitFixture fixture(cv::Mat(80, 100, CV_32F, cv::Scalar(2.0f)));
  fixture.views[0].image.colRange(49, 53).setTo(cv::Scalar(250, 250, 250));
  EXPECT_EQ(TornFraction(fixture.frame, fixture.camera, fixture.views, fixture.depth), 0.0);
}

TEST(PathMeasuresTest, FlickerCountsWhatChangesOnceTheMotionIsTakenOut) {
  // A textured wall at 2 m seen from two cameras 1 cm apart: the second frame is the first moved
  // by its disparity (0.5 px), so nothing flickers; a block repainted does.
  VirtualCamera first, second;
  first.camera = second.camera = CameraModel::Pinhole(120, 90, 100);
  second.cam_from_world = Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-0.02, 0, 0));  // 1 px
  cv::Mat texture(90, 121, CV_8UC3);
  cv::randu(texture, 0, 255);
  cv::GaussianBlur(texture, texture, cv::Size(5, 5), 1.5);
  const cv::Mat previous = texture.colRange(0, 120).clone();
  FrameRender current;
  current.bgr = texture.colRange(1, 121).clone();
  current.depth_m = cv::Mat(90, 120, CV_32F, cv::Scalar(2.0f));
  EXPECT_LT(FlickerFraction(previous, first, current, second), 0.001);
  current.bgr(cv::Rect(30, 30, 20, 20)).setTo(cv::Scalar(255, 0, 255));
  EXPECT_NEAR(FlickerFraction(previous, first, current, second), 400.0 / (119 * 90), 0.01);
}

TEST(LeaveOneOutTest, TwoViewsCannotBeScored) {
  RealSet set;
  set.name = "two";
  set.capture.kind = FrameSetKind::kImageSet;
  set.capture.frames.resize(2);
  const StatusOr<LeaveOneOutResult> result = EvaluateLeaveOneOut(set, {});
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(result.status().message().find("at least 3"), std::string::npos);
}

// The still life shot by hand from four places 6 cm apart (noise-free, focal as EXIF gives it).
RealSet SimulatedHandheldSet() {
  StatusOr<sim::Scene> scene = sim::LoadScene(sim::ScenesDir() / "still_life.json");
  EXPECT_TRUE(scene.ok()) << scene.status().ToString();
  const CameraModel camera = CameraModel::Pinhole(320, 240, 280);
  RealSet set;
  set.name = "sim still_life hand-held";
  set.capture.kind = FrameSetKind::kImageSet;
  if (!scene.ok()) return set;
  const double xs[] = {-0.09, -0.03, 0.03, 0.09};
  for (int i = 0; i < 4; ++i) {
    const Eigen::Quaterniond turn(Eigen::AngleAxisd((i - 1.5) * -0.4 * M_PI / 180, Eigen::Vector3d::UnitY()));
    const Rigid3 pose(turn, -(turn * Eigen::Vector3d(xs[i], 0.004 * (i % 2), 0)));
    StatusOr<sim::RenderedView> shot = sim::RenderView(*scene, camera, pose);
    EXPECT_TRUE(shot.ok());
    if (!shot.ok()) return set;
    Frame frame;
    frame.image = FromBgr(shot->bgr, PixelFormat::kRgb888).value();
    frame.sequence = i;
    frame.focal_length_px = camera.fx;
    set.capture.frames.push_back(frame);
    set.view_names.push_back("shot " + std::to_string(i));
  }
  return set;
}

// Every photo held out in turn must be rendered better than the nearest photo shows it, and
// better than one plane can warp it.
TEST(LeaveOneOutTest, SimulatedHandheldBeatsBothBaselines) {
  RealSet set = SimulatedHandheldSet();
  ASSERT_EQ(set.capture.frames.size(), 4u);
  set.held_out = HeldOutViews(4);
  const StatusOr<LeaveOneOutResult> result = EvaluateLeaveOneOut(set, {});
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  ASSERT_EQ(result->cases.size(), 4u);
  const ImageScores ours = MeanScores(result->cases, &LeaveOneOutCase::ours);
  const ImageScores nearest = MeanScores(result->cases, &LeaveOneOutCase::nearest);
  const ImageScores plane = MeanScores(result->cases, &LeaveOneOutCase::plane);
  EXPECT_GT(ours.psnr_db, nearest.psnr_db + 3) << "plane " << plane.psnr_db;
  EXPECT_GT(ours.psnr_db, plane.psnr_db);
  EXPECT_GT(ours.ssim, nearest.ssim);
}

// The automatic clip's figures: preview frames measure double images; offline frames (the paper's
// 6.2, which the compositor that measures them does not draw) say they are unmeasured, not 0.
TEST(PathEvalTest, OnlyPreviewFramesMeasureDoubleImages) {
  const RealSet set = SimulatedHandheldSet();
  ASSERT_EQ(set.capture.frames.size(), 4u);
  for (const RenderQuality quality : {RenderQuality::kPreview, RenderQuality::kOffline}) {
    PathEvalOptions options;
    options.pipeline.direct.duration_s = 0.5;
    options.pipeline.direct.fps = 6;
    options.pipeline.render.quality = quality;
    const StatusOr<PathResult> result = EvaluatePath(set, options);
    ASSERT_TRUE(result.ok()) << result.status().ToString();
    ASSERT_TRUE(result->measured) << result->mode << ": " << result->reason;
    EXPECT_EQ(result->double_measured, quality == RenderQuality::kPreview);
    if (!result->double_measured) {
      EXPECT_EQ(result->double_image, 0);
    }
  }
}

TEST(LeaveOneOutTest, RealOfficeSetBeatsTheNearestView) {
  const fs::path dir = sim::SharedDataDir() / "handheld" / "kpankov_office_4views";
  if (!fs::exists(dir)) GTEST_SKIP() << dir.string() << " is absent (the shared real data sits beside the project)";
  StatusOr<RealSet> set = LoadRealSet(dir, "handheld/kpankov_office_4views");
  ASSERT_TRUE(set.ok()) << set.status().ToString();
  EXPECT_EQ(set->capture.frames.size(), 4u);
  const StatusOr<LeaveOneOutResult> result = EvaluateLeaveOneOut(*set, {});
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  EXPECT_EQ(result->num_posed, 4);
  EXPECT_EQ(result->cases.size(), 4u);
  const ImageScores ours = MeanScores(result->cases, &LeaveOneOutCase::ours);
  const ImageScores nearest = MeanScores(result->cases, &LeaveOneOutCase::nearest);
  EXPECT_GT(ours.psnr_db, nearest.psnr_db);
}

}  // namespace
}  // namespace px::eval
