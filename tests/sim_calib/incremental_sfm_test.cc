// Hand-held structure from motion on simulated image sets with known cameras: tiny baselines
// (the paper's 3-4 inches), focal length known or self-calibrated, and the sets that must fail
// or degrade with a clear message (pure rotation, an image of another scene, a blank image).
#include "pipeline/calib/incremental_sfm.h"

#include <algorithm>
#include <cstdio>

#include <gtest/gtest.h>

#include "eval/calib/pose_alignment.h"
#include "eval/calib/sim_lattice_shot.h"
#include "pipeline/core/pixel_format.h"
#include "pipeline/run/pipeline.h"
#include "sim/synthetic/data_paths.h"
#include "sim/synthetic/ray_caster.h"
#include "sim/synthetic/scene_json.h"
#include "tests/testing/temp_dir.h"

namespace px::sim_calib {
namespace {

constexpr double kFocalPx = 560.0;

Eigen::Quaterniond Turn(double rx_deg, double ry_deg, double rz_deg) {
  const double k = M_PI / 180.0;
  return Eigen::Quaterniond(Eigen::AngleAxisd(rx_deg * k, Eigen::Vector3d::UnitX()) *
                            Eigen::AngleAxisd(ry_deg * k, Eigen::Vector3d::UnitY()) *
                            Eigen::AngleAxisd(rz_deg * k, Eigen::Vector3d::UnitZ()));
}

struct ImageSet {
  std::vector<calib::SfmImage> images;
  std::vector<Rigid3> truth;
  CameraModel camera;
};

// `centres_m` and turns (degrees about x, y, z) per view, all looking down +z at still_life.
ImageSet Render(const std::string& scene_name, const std::vector<Eigen::Vector3d>& centres_m,
                const std::vector<Eigen::Vector3d>& turns_deg, bool known_focal) {
  ImageSet set;
  set.camera = CameraModel::Pinhole(640, 480, kFocalPx);
  StatusOr<sim::Scene> scene = sim::LoadScene(scene_name.find('/') != std::string::npos
                                                   ? std::filesystem::path(scene_name)
                                                   : sim::ScenesDir() / (scene_name + ".json"));
  EXPECT_TRUE(scene.ok()) << scene.status().ToString();
  if (!scene.ok()) return set;
  for (size_t i = 0; i < centres_m.size(); ++i) {
    const Eigen::Quaterniond rotation = Turn(turns_deg[i].x(), turns_deg[i].y(), turns_deg[i].z());
    const Rigid3 cam_from_world(rotation, -(rotation * centres_m[i]));
    StatusOr<sim::RenderedView> view = sim::RenderView(*scene, set.camera, cam_from_world);
    EXPECT_TRUE(view.ok()) << view.status().ToString();
    if (!view.ok()) return set;
    calib::SfmImage image;
    image.image = view->bgr;
    cv::Mat noise(image.image.size(), CV_16SC3);
    cv::RNG rng(100 + i);
    rng.fill(noise, cv::RNG::NORMAL, 0, 2.0);
    cv::Mat noisy;
    image.image.convertTo(noisy, CV_16SC3);
    noisy += noise;
    noisy.convertTo(image.image, CV_8UC3);
    if (known_focal) image.intrinsics = set.camera;
    set.images.push_back(image);
    set.truth.push_back(cam_from_world);
  }
  return set;
}

// Four hand-held shots 8 cm apart (about 3 inches), each turned by up to 2 degrees.
ImageSet HandHeld(bool known_focal, const std::string& scene = "still_life") {
  return Render(scene,
                {{-0.12, 0.0, 0.0}, {-0.04, 0.01, 0.005}, {0.04, -0.005, -0.01}, {0.12, 0.008, 0.0}},
                {{0.5, 1.5, -0.3}, {-0.8, 0.4, 0.6}, {1.2, -1.0, 0.2}, {-0.3, -2.0, -0.7}}, known_focal);
}

struct Figures {
  double rotation_deg = 0, centre = 0, focal = 0;
};

Figures Compare(const calib::SfmResult& result, const ImageSet& set) {
  std::vector<Rigid3> est;
  std::vector<double> est_f, ref_f;
  for (const calib::SfmView& view : result.views) {
    est.push_back(view.cam_from_world);
    est_f.push_back(view.camera.fx);
    ref_f.push_back(set.camera.fx);
  }
  StatusOr<eval::PoseErrors> errors = eval::ComparePoses(est, set.truth, est_f, ref_f);
  EXPECT_TRUE(errors.ok()) << errors.status().ToString();
  if (!errors.ok()) return {};
  return {eval::PoseErrors::Max(errors->rotation_deg), eval::PoseErrors::Max(errors->centre_relative),
          eval::PoseErrors::Max(errors->focal_relative)};
}

void Print(const char* name, const calib::SfmResult& result, const Figures& figures) {
  const calib::SfmReport& r = result.report;
  std::printf("%s: %d/%d registered, %d points, RMS %.3f px, initial pair %d-%d (parallax %.1f px, %.1fx noise), "
              "focal %.1f px (%s), %.0f ms; rotation %.3f deg, centre %.3f baselines, focal %.2f %%\n",
              name, r.num_registered, r.num_images, r.num_points, r.rms_px, r.initial_image_a, r.initial_image_b,
              r.initial_parallax_px, r.initial_parallax_ratio, result.views[0].camera.fx, r.focal_source.c_str(),
              r.total_ms, figures.rotation_deg, figures.centre, 100 * figures.focal);
  for (const std::string& warning : r.warnings) std::printf("  warning: %s\n", warning.c_str());
}

TEST(IncrementalSfmSimTest, TinyBaselineWithKnownFocal) {
  const ImageSet set = HandHeld(/*known_focal=*/true);
  ASSERT_EQ(set.images.size(), 4u);
  StatusOr<calib::SfmResult> result = calib::RunIncrementalSfm(set.images, calib::SfmOptions());
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  ASSERT_TRUE(result->report.success) << result->report.failure;
  const Figures figures = Compare(*result, set);
  Print("known focal", *result, figures);
  EXPECT_EQ(result->report.num_registered, 4);
  EXPECT_EQ(result->report.focal_source, "metadata");
  EXPECT_LT(figures.rotation_deg, 0.1);
  EXPECT_LT(figures.centre, 0.05);
  EXPECT_LT(figures.focal, 0.01);
  EXPECT_LT(result->report.rms_px, 0.8);
  // The scale: median depth 1 (the scene's objects lie 0.85-4 m away).
  for (const calib::SfmView& view : result->views) {
    EXPECT_GT(view.depth_near, 0.1);
    EXPECT_LT(view.depth_far, 20.0);
  }
}

TEST(IncrementalSfmSimTest, TinyBaselineSelfCalibrated) {
  const ImageSet set = HandHeld(/*known_focal=*/false);
  StatusOr<calib::SfmResult> result = calib::RunIncrementalSfm(set.images, calib::SfmOptions());
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  ASSERT_TRUE(result->report.success) << result->report.failure;
  const Figures figures = Compare(*result, set);
  Print("self-calibrated", *result, figures);
  EXPECT_EQ(result->report.num_registered, 4);
  EXPECT_EQ(result->report.focal_source, "self-calibrated");
  EXPECT_LT(figures.rotation_deg, 0.2);
  EXPECT_LT(figures.focal, 0.05);
}

// Three views translated along a line without rotation (a row of a lattice): poses are found,
// but a self-calibrated focal length trades exactly with depth, so it is reported unobservable;
// with the focal length from metadata it is not.
TEST(IncrementalSfmSimTest, PureTranslationReportsTheFocalLengthUnobservable) {
  const std::vector<Eigen::Vector3d> centres = {{-0.08, 0, 0}, {0, 0, 0}, {0.08, 0, 0}};
  const std::vector<Eigen::Vector3d> no_turns(3, Eigen::Vector3d::Zero());
  for (bool known_focal : {false, true}) {
    const ImageSet set = Render("still_life", centres, no_turns, known_focal);
    StatusOr<calib::SfmResult> result = calib::RunIncrementalSfm(set.images, calib::SfmOptions());
    ASSERT_TRUE(result.ok()) << result.status().ToString();
    ASSERT_TRUE(result->report.success) << result->report.failure;
    const Figures figures = Compare(*result, set);
    Print(known_focal ? "translation, known focal" : "translation, self-calibrated", *result, figures);
    EXPECT_EQ(result->report.num_registered, 3);
    EXPECT_LT(result->report.max_view_rotation_deg, 0.5);
    EXPECT_EQ(result->report.focal_observable, known_focal);
    bool warned = false;
    for (const std::string& warning : result->report.warnings) {
      warned |= warning.find("focal length is unobservable") != std::string::npos;
    }
    EXPECT_EQ(warned, !known_focal);
    if (known_focal) {
      EXPECT_LT(figures.focal, 0.01);
    }
  }
}

class CountingSink : public FrameSink {
 public:
  Status Consume(int, const cv::Mat&) override {
    ++frames;
    return OkStatus();
  }
  int frames = 0;
};

// The hand-held set as a tethered camera delivers it (an image set, intrinsics from a
// calibration with one lens per image, no poses): structure from motion, depth and a clip.
TEST(IncrementalSfmSimTest, ImageSetRunsThroughThePipeline) {
  const ImageSet set = HandHeld(/*known_focal=*/true);
  FrameSet capture;
  capture.kind = FrameSetKind::kImageSet;
  capture.capture_id = 4;
  RigCalibration intrinsics;
  for (const calib::SfmImage& image : set.images) {
    Frame frame;
    frame.image = FromBgr(image.image, PixelFormat::kRgb888).value();
    capture.frames.push_back(std::move(frame));
    intrinsics.lenses.push_back(LensCalibration{});
    intrinsics.lenses.back().camera = set.camera;
  }
  PipelineOptions options;
  options.direct.fps = 5;
  options.direct.duration_s = 1;
  CountingSink sink;
  StatusOr<PipelineReport> report = RunPipeline(capture, intrinsics, options, &sink);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  std::printf("pipeline: %s: %s\n", report->calibration.c_str(), report->calibration_summary.c_str());
  for (const std::string& warning : report->warnings) std::printf("  warning: %s\n", warning.c_str());
  EXPECT_EQ(report->calibration, "structure from motion");
  EXPECT_NE(report->calibration_summary.find("4 of 4 images registered"), std::string::npos);
  EXPECT_EQ(report->num_views, 4);
  EXPECT_EQ(sink.frames, 5);
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
  PipelineOptions options;
  options.direct.fps = 5;
  options.direct.duration_s = 1;
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
    return std::any_of(report->warnings.begin(), report->warnings.end(),
                       [&](const std::string& w) { return w.find(text) != std::string::npos; });
  };
  EXPECT_TRUE(warned("no factory rig calibration: lattice found blind (3x3"));
  EXPECT_TRUE(warned("focal length is unobservable"));
}

TEST(IncrementalSfmSimTest, PureRotationFailsWithNoParallax) {
  const ImageSet set = Render("still_life", std::vector<Eigen::Vector3d>(3, Eigen::Vector3d::Zero()),
                              {{0, -3, 0}, {1, 0, 0.5}, {0, 3, -0.5}}, /*known_focal=*/true);
  StatusOr<calib::SfmResult> result = calib::RunIncrementalSfm(set.images, calib::SfmOptions());
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  EXPECT_FALSE(result->report.success);
  std::printf("pure rotation: %s\n", result->report.failure.c_str());
  EXPECT_NE(result->report.failure.find("no parallax"), std::string::npos) << result->report.failure;
}

TEST(IncrementalSfmSimTest, ForeignAndBlankImagesAreLeftOutByName) {
  ImageSet set = HandHeld(/*known_focal=*/true);
  const ImageSet other = Render("two_faces", {{0.5, 0.2, -1.0}}, {{0, 25, 0}}, true);
  ASSERT_EQ(other.images.size(), 1u);
  set.images.push_back(other.images[0]);
  calib::SfmImage blank;
  blank.image = cv::Mat(480, 640, CV_8UC3, cv::Scalar(128, 128, 128));
  blank.intrinsics = set.camera;
  set.images.push_back(blank);
  calib::SfmImage overexposed;  // blown out: clipped white but for a smooth ramp on the left
  overexposed.image = cv::Mat(480, 640, CV_8UC3, cv::Scalar(255, 255, 255));
  for (int x = 0; x < 200; ++x) overexposed.image.col(x).setTo(cv::Scalar::all(180 + 75 * x / 200));
  overexposed.intrinsics = set.camera;
  set.images.push_back(overexposed);
  StatusOr<calib::SfmResult> result = calib::RunIncrementalSfm(set.images, calib::SfmOptions());
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  ASSERT_TRUE(result->report.success) << result->report.failure;
  for (const std::string& warning : result->report.warnings) std::printf("warning: %s\n", warning.c_str());
  EXPECT_EQ(result->report.num_registered, 4);
  EXPECT_FALSE(result->views[4].registered);
  EXPECT_NE(result->views[4].note.find("matches no other image"), std::string::npos) << result->views[4].note;
  EXPECT_FALSE(result->views[5].registered);
  EXPECT_NE(result->views[5].note.find("blank"), std::string::npos) << result->views[5].note;
  EXPECT_FALSE(result->views[6].registered);
  EXPECT_NE(result->views[6].note.find("overexposed"), std::string::npos) << result->views[6].note;
}

// Every image of the hand-held set shows one textured wall: the poses are still found (a plane
// fixes them), and the report warns that the scene is planar so a self-calibrated focal length
// would be unreliable.
TEST(IncrementalSfmSimTest, AllPlanarSetRegistersWithAWarning) {
  px::testing::TempDir temp;
  const std::filesystem::path scene = temp.path() / "wall.json";
  eval::WritePlaneScene(scene, 1.5, R"({"type": "noise", "rgb_a": [220, 200, 160], "rgb_b": [40, 50, 70],
      "scale_m": 0.5, "octaves": 8, "persistence": 0.7, "contrast": 2.0, "seed": 3})");
  const ImageSet set = HandHeld(/*known_focal=*/true, scene.string());
  StatusOr<calib::SfmResult> result = calib::RunIncrementalSfm(set.images, calib::SfmOptions());
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  ASSERT_TRUE(result->report.success) << result->report.failure;
  const Figures figures = Compare(*result, set);
  Print("planar wall", *result, figures);
  EXPECT_EQ(result->report.num_registered, 4);
  EXPECT_LT(figures.rotation_deg, 0.5);
  EXPECT_TRUE(std::any_of(result->report.warnings.begin(), result->report.warnings.end(), [](const std::string& w) {
    return w.find("sees a plane or a distant scene") != std::string::npos;
  })) << ::testing::PrintToString(result->report.warnings);
}

TEST(IncrementalSfmSimTest, TexturelessSetFailsWithTooFewFeatures) {
  std::vector<calib::SfmImage> images(3);
  for (calib::SfmImage& image : images) image.image = cv::Mat(480, 640, CV_8UC3, cv::Scalar(250, 250, 250));
  StatusOr<calib::SfmResult> result = calib::RunIncrementalSfm(images, calib::SfmOptions());
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  EXPECT_FALSE(result->report.success);
  EXPECT_NE(result->report.failure.find("too few features"), std::string::npos) << result->report.failure;
  EXPECT_FALSE(calib::RunIncrementalSfm({}, calib::SfmOptions()).ok());
}

}  // namespace
}  // namespace px::sim_calib
