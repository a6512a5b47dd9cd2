#include "pipeline/render/cpu_scene_renderer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <opencv2/core/utility.hpp>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "pipeline/render/layered_from_depth.h"
#include "pipeline/render/layered_scene.h"
#include "pipeline/render/render_test_util.h"

namespace px {
namespace {

using render::testing::AwayFromEdges;
using render::testing::MakeLayeredLattice;
using render::testing::MaskedPsnr;
using render::testing::PlaneScene;

// Half the Pop9 tile (640x480, f 560) keeps the tests fast with the same angles.
const CameraModel kCamera = CameraModel::Pinhole(320, 240, 280);
constexpr double kBaselineM = 0.025;

VirtualCamera At(const CameraModel& camera, const Rigid3& pose) {
  VirtualCamera v;
  v.camera = camera;
  v.cam_from_world = pose;
  return v;
}

class CpuSceneRendererTest : public ::testing::Test {
 protected:
  void SetUp() override { MakeLayeredLattice(scene_, 3, 3, kBaselineM, kCamera, &views_, &layers_); }
  std::unique_ptr<CpuSceneRenderer> Make(const RenderOptions& options = {}) {
    auto renderer = CpuSceneRenderer::Create(views_, layers_, options);
    EXPECT_TRUE(renderer.ok()) << renderer.status().ToString();
    return renderer.ok() ? std::move(renderer).value() : nullptr;
  }
  PlaneScene scene_;
  std::vector<View> views_;
  std::vector<LayeredDepthView> layers_;
};

TEST_F(CpuSceneRendererTest, ViewBetweenSourcesMatchesTheExactRender) {
  // Between the lenses, turned 1 degree and zoomed 5 %: exercises the full warp.
  const Eigen::Vector3d centre(0.011, 0.006, 0.0);
  const Eigen::Quaterniond rotation(Eigen::AngleAxisd(M_PI / 180, Eigen::Vector3d::UnitY()));
  const Rigid3 pose(rotation, -(rotation * centre));
  CameraModel camera = kCamera;
  camera.fx = camera.fy = 294;
  for (RenderQuality quality : {RenderQuality::kPreview, RenderQuality::kOffline}) {
    RenderOptions options;
    options.quality = quality;
    auto renderer = Make(options);
    ASSERT_NE(renderer, nullptr);
    StatusOr<FrameRender> frame = renderer->Render(At(camera, pose));
    for (int i = 0; i < 5; ++i) frame = renderer->Render(At(camera, pose));
    ASSERT_TRUE(frame.ok()) << frame.status().ToString();
    cv::Mat want_bgr, want_depth;
    scene_.Render(camera, pose, &want_bgr, &want_depth);
    const cv::Mat interior = AwayFromEdges(want_depth);
    const double psnr_interior = MaskedPsnr(frame->bgr, want_bgr, interior);
    const double psnr_all = MaskedPsnr(frame->bgr, want_bgr);
    const CpuFrameStats& st = renderer->last_frame();
    std::printf("weights %.1f setup %.1f composite %.1f holes %.1f effects %.1f segs %d views %d\n",
                st.weights_ms,
                st.setup_ms,
                st.composite_ms,
                st.holes_ms,
                st.effects_ms,
                st.segments_drawn,
                st.views_drawn);
    std::printf("%s: between sources PSNR %.2f dB interior, %.2f dB all, holes %.4f, %.1f ms\n",
                std::string(RenderQualityName(quality)).c_str(),
                psnr_interior,
                psnr_all,
                frame->holes.hole_ratio,
                renderer->last_frame().total_ms);
    EXPECT_GT(psnr_interior, 44.0);
    EXPECT_GT(psnr_all, 35.0);
    EXPECT_LT(frame->holes.hole_ratio, 0.02);
  }
}

TEST_F(CpuSceneRendererTest, AtASourceViewTheRenderIsThatView) {
  auto renderer = Make();
  ASSERT_NE(renderer, nullptr);
  const View& centre = views_[4];
  StatusOr<FrameRender> frame = renderer->Render(At(centre.camera, centre.cam_from_world));
  ASSERT_TRUE(frame.ok()) << frame.status().ToString();
  const double psnr = MaskedPsnr(frame->bgr, centre.image);
  std::printf("at the centre lens: PSNR %.2f dB vs its image, holes %.5f\n", psnr, frame->holes.hole_ratio);
  // Weight 1 on the centre view at every pixel: its segments resampled at their own pixels.
  EXPECT_GT(psnr, 45.0);
  EXPECT_EQ(frame->holes.hole_ratio, 0.0);
  ASSERT_FALSE(frame->sources.empty());
  EXPECT_EQ(frame->sources.front(), centre.id);
}

// At a depth edge's matte a view sees its front layer's colour over its back layer's, each with
// its own share (the depth stage's two layers). The offline soft z must keep that view's own
// matting, as the preview's rendering buffers do, and not drop the back layer as a surface
// hidden behind the front one. Here each band pixel's layers are pushed 40 levels apart around
// its colour, so that only both layers together give the view's image back.
TEST_F(CpuSceneRendererTest, OfflineKeepsEachViewsBoundaryMatteAsThePreviewDoes) {
  LayeredFromDepthOptions matte;
  matte.edge_front_weight = 0.5;
  render::testing::MakeLayeredLattice(scene_, 3, 3, kBaselineM, kCamera, &views_, &layers_, matte);
  cv::Mat band(kCamera.height, kCamera.width, CV_8U, cv::Scalar(0));
  for (LayeredDepthView& view : layers_) {
    for (int y = 0; y < kCamera.height; ++y) {
      for (int x = 0; x < kCamera.width; ++x) {
        if (view.layers[1].weight.at<float>(y, x) != 0.5f || view.layers[0].weight.at<float>(y, x) != 0.5f) continue;
        cv::Vec3b& front = view.layers[0].colour.at<cv::Vec3b>(y, x);
        cv::Vec3b& back = view.layers[1].colour.at<cv::Vec3b>(y, x);
        for (int c = 0; c < 3; ++c) {
          const int mixed = (front[c] + back[c]) / 2;
          const int spread = std::min({40, mixed, 255 - mixed});
          front[c] = static_cast<uint8_t>(mixed + spread);
          back[c] = static_cast<uint8_t>(mixed - spread);
        }
        if (view.id == views_[4].id) band.at<uint8_t>(y, x) = 255;
      }
    }
  }
  ASSERT_GT(cv::countNonZero(band), 100);
  const View& centre = views_[4];
  for (RenderQuality quality : {RenderQuality::kPreview, RenderQuality::kOffline}) {
    RenderOptions options;
    options.quality = quality;
    auto renderer = Make(options);
    ASSERT_NE(renderer, nullptr);
    StatusOr<FrameRender> frame = renderer->Render(At(centre.camera, centre.cam_from_world));
    ASSERT_TRUE(frame.ok()) << frame.status().ToString();
    const double psnr = MaskedPsnr(frame->bgr, centre.image, band);
    std::printf("%s at the centre lens: PSNR %.2f dB on its %d matte pixels\n",
                std::string(RenderQualityName(quality)).c_str(),
                psnr,
                cv::countNonZero(band));
    EXPECT_GT(psnr, 40.0) << RenderQualityName(quality);
  }
}

TEST_F(CpuSceneRendererTest, CoverageAgreesWithRenderAndIsCheapAtReducedSize) {
  auto renderer = Make();
  ASSERT_NE(renderer, nullptr);
  // 30 cm behind the lattice: the wider view sees past the sources' fields of view at its borders.
  const Rigid3 pose(Eigen::Quaterniond::Identity(), -Eigen::Vector3d(0.01, 0.0, -0.3));
  StatusOr<FrameRender> frame = renderer->Render(At(kCamera, pose));
  ASSERT_TRUE(frame.ok()) << frame.status().ToString();
  StatusOr<CoverageReport> full = renderer->Coverage(kCamera, pose);
  ASSERT_TRUE(full.ok()) << full.status().ToString();
  EXPECT_GT(frame->holes.hole_ratio, 0.01);
  EXPECT_NEAR(full->hole_ratio, frame->holes.hole_ratio, 1e-9);
  EXPECT_NEAR(full->hole_score, frame->holes.hole_score, 1e-9);
  EXPECT_EQ(full->width, 320);
  // At 1/8 size (the coarse scene: 32 px blocks) the ratio is nearly the same; H(V) scales with
  // the cube of the size (d^3).
  ASSERT_NE(renderer->coarse_scene(), nullptr);
  size_t fine_segments = 0, coarse_segments = 0;
  for (const render::SceneView& view : renderer->scene().views()) fine_segments += view.segments.size();
  for (const render::SceneView& view : renderer->coarse_scene()->views()) coarse_segments += view.segments.size();
  EXPECT_LT(coarse_segments * 8, fine_segments);
  StatusOr<CoverageReport> small = renderer->Coverage(kCamera.Scaled(0.125), pose);
  ASSERT_TRUE(small.ok()) << small.status().ToString();
  EXPECT_EQ(small->width, 40);
  EXPECT_NEAR(small->hole_ratio, full->hole_ratio, 0.02);
  std::printf("coverage: full %.4f H %.3f; 1/8 %.4f H %.5f (x512 = %.3f); segments %zu, coarse %zu\n",
              full->hole_ratio,
              full->hole_score,
              small->hole_ratio,
              small->hole_score,
              512 * small->hole_score,
              fine_segments,
              coarse_segments);
}

// The coarse scene is made from the planes the renderer draws, not from depth_m: the depth stage
// holds depth_m to its swept range, while a plane tilted past the range's end is drawn where it
// lies. With depth_m at half the planes' depth, the 1/8-size coverage still reads what the
// full-size frame leaves open.
TEST_F(CpuSceneRendererTest, ReducedSizeCoverageFollowsTheDrawnPlanes) {
  for (LayeredDepthView& layered : layers_) layered.depth_m *= 0.5;
  auto renderer = Make();
  ASSERT_NE(renderer, nullptr);
  const Rigid3 pose(Eigen::Quaterniond::Identity(), -Eigen::Vector3d(0.01, 0.0, -0.3));
  StatusOr<CoverageReport> full = renderer->Coverage(kCamera, pose);
  StatusOr<CoverageReport> small = renderer->Coverage(kCamera.Scaled(0.125), pose);
  ASSERT_TRUE(full.ok() && small.ok());
  std::printf("coverage with depth_m halved: full %.4f, 1/8 %.4f\n", full->hole_ratio, small->hole_ratio);
  EXPECT_GT(full->hole_ratio, 0.01);
  EXPECT_NEAR(small->hole_ratio, full->hole_ratio, 0.02);
}

// Coverage() keeps no state between calls: the direction stage's search calls it from two
// threads at once (and a Render may run beside it; Render itself is not re-entrant). Viewpoints spread behind and
// across the lattice, at full and 1/8 size, give the same reports concurrently as one after another.
TEST_F(CpuSceneRendererTest, CoverageGivesTheSameReportsFromSeveralThreadsAtOnce) {
  auto renderer = Make();
  ASSERT_NE(renderer, nullptr);
  std::vector<std::pair<CameraModel, Rigid3>> probes;
  for (int i = 0; i < 24; ++i) {
    const Eigen::Vector3d centre(0.01 * (i % 5 - 2), 0.008 * (i % 3 - 1), -0.02 * (i % 7));
    probes.emplace_back(i % 2 == 0 ? kCamera : kCamera.Scaled(0.125), Rigid3(Eigen::Quaterniond::Identity(), -centre));
  }
  std::vector<CoverageReport> serial;
  for (const auto& [camera, pose] : probes) {
    StatusOr<CoverageReport> report = renderer->Coverage(camera, pose);
    ASSERT_TRUE(report.ok()) << report.status().ToString();
    serial.push_back(*report);
  }
  std::vector<StatusOr<CoverageReport>> concurrent(probes.size(), InternalError("not measured"));
  const auto measure = [&](size_t first) {
    for (size_t i = first; i < probes.size(); i += 2)
      concurrent[i] = renderer->Coverage(probes[i].first, probes[i].second);
  };
  // As the search runs its two chains: side by side in a cv::parallel_for_, whose nested loops
  // inside Coverage() then run on the calling thread; a Render on a thread of its own beside them.
  std::thread render([&] { ASSERT_TRUE(renderer->Render(At(kCamera, probes[3].second)).ok()); });
  cv::parallel_for_(
      cv::Range(0, 2),
      [&](const cv::Range& range) {
        for (int chain = range.start; chain < range.end; ++chain) measure(chain);
      },
      2);
  render.join();
  for (size_t i = 0; i < probes.size(); ++i) {
    ASSERT_TRUE(concurrent[i].ok()) << concurrent[i].status().ToString();
    EXPECT_EQ(concurrent[i]->width, serial[i].width) << "probe " << i;
    EXPECT_EQ(concurrent[i]->hole_ratio, serial[i].hole_ratio) << "probe " << i;
    EXPECT_EQ(concurrent[i]->hole_score, serial[i].hole_score) << "probe " << i;
  }
}

TEST_F(CpuSceneRendererTest, ColourEffectsAndDepthOfFieldReachTheFrame) {
  auto renderer = Make();
  ASSERT_NE(renderer, nullptr);
  const Rigid3 pose(Eigen::Quaterniond::Identity(), -Eigen::Vector3d(0.005, 0.0, 0.0));
  StatusOr<FrameRender> plain = renderer->Render(At(kCamera, pose));
  ASSERT_TRUE(plain.ok());
  // Desaturate everything but the foreground box (z = 1 m): the background turns grey.
  VirtualCamera camera = At(kCamera, pose);
  ColorEffect effect;
  effect.kind = ColorEffectKind::kSaturation;
  effect.amount = 0;
  effect.region_min_in_world = Eigen::Vector3d(-0.25, -0.15, 0.95);
  effect.region_max_in_world = Eigen::Vector3d(0.15, 0.15, 1.05);
  effect.falloff_m = 0.02;
  effect.invert = true;
  camera.effects = {effect};
  StatusOr<FrameRender> effected = renderer->Render(camera);
  ASSERT_TRUE(effected.ok()) << effected.status().ToString();
  const auto spread = [](const cv::Vec3b& c) { return std::max({c[0], c[1], c[2]}) - std::min({c[0], c[1], c[2]}); };
  const cv::Point background(5, 5), foreground(140, 120);  // the rectangle spans x 102..186, y 86..153
  ASSERT_GT(plain->depth_m.at<float>(background), 2.5f);
  ASSERT_LT(plain->depth_m.at<float>(foreground), 1.5f);
  EXPECT_LE(spread(effected->bgr.at<cv::Vec3b>(background)), 1);
  EXPECT_EQ(effected->bgr.at<cv::Vec3b>(foreground), plain->bgr.at<cv::Vec3b>(foreground));
  // Depth of field focused on the foreground: it stays as it was, the background blurs.
  VirtualCamera lens = At(kCamera, pose);
  lens.aperture_m = 0.03;
  lens.focus_depth_m = 1.0;
  StatusOr<FrameRender> dof = renderer->Render(lens);
  ASSERT_TRUE(dof.ok()) << dof.status().ToString();
  const cv::Rect fg_patch(130, 105, 20, 20), bg_patch(10, 10, 40, 40);
  cv::Mat diff;
  cv::absdiff(dof->bgr(fg_patch), plain->bgr(fg_patch), diff);
  EXPECT_LE(cv::norm(diff, cv::NORM_INF), 1.0);
  cv::absdiff(dof->bgr(bg_patch), plain->bgr(bg_patch), diff);
  EXPECT_GT(cv::norm(diff, cv::NORM_INF), 3.0);
}

// Bad input (issue item 9): clear errors or honest degraded frames, never a crash or a hang.
TEST_F(CpuSceneRendererTest, AViewWithoutValidDepthIsLeftOutWithAWarning) {
  std::vector<View> views = views_;
  std::vector<LayeredDepthView> layers = layers_;
  DepthMap empty;
  empty.id = views[2].id;
  empty.depth_m = cv::Mat(kCamera.height, kCamera.width, CV_32F, cv::Scalar(0));
  empty.depth_m.at<float>(7, 7) = std::numeric_limits<float>::quiet_NaN();
  StatusOr<LayeredDepthView> layered = LayeredDepthFromDepthMap(views[2], empty);
  ASSERT_TRUE(layered.ok()) << layered.status().ToString();
  layers[2] = *layered;
  auto renderer = CpuSceneRenderer::Create(views, layers, RenderOptions());
  ASSERT_TRUE(renderer.ok()) << renderer.status().ToString();
  EXPECT_EQ((*renderer)->scene().views().size(), 8u);
  ASSERT_FALSE((*renderer)->warnings().empty());
  EXPECT_NE((*renderer)->warnings().back().find("no valid depth"), std::string::npos);
  StatusOr<FrameRender> frame = (*renderer)->Render(At(kCamera, views[4].cam_from_world));
  ASSERT_TRUE(frame.ok()) << frame.status().ToString();
  EXPECT_GT(MaskedPsnr(frame->bgr, views[4].image), 40.0);
  // No view with depth at all: an error that says so.
  std::vector<LayeredDepthView> none(layers.size(), *layered);
  for (size_t i = 0; i < none.size(); ++i) none[i].id = views[i].id;
  auto nothing = CpuSceneRenderer::Create(views, none, RenderOptions());
  ASSERT_FALSE(nothing.ok());
  EXPECT_NE(nothing.status().message().find("valid depth"), std::string::npos) << nothing.status().ToString();
}

TEST_F(CpuSceneRendererTest, NanPlanesAndWeightsAreDroppedNotDrawn) {
  std::vector<LayeredDepthView> layers = layers_;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  // Poison half of the centre view's segments and some of its layer weights.
  LayeredDepthView& centre = layers[4];
  for (size_t s = 0; s < centre.segments.size(); s += 2) centre.segments[s].inv_depth_c = nan;
  centre.layers[0].weight(cv::Rect(0, 0, 40, 40)).setTo(nan);
  auto renderer = CpuSceneRenderer::Create(views_, layers, RenderOptions());
  ASSERT_TRUE(renderer.ok()) << renderer.status().ToString();
  ASSERT_GE((*renderer)->warnings().size(), 2u);
  StatusOr<FrameRender> frame = (*renderer)->Render(At(kCamera, views_[4].cam_from_world));
  ASSERT_TRUE(frame.ok()) << frame.status().ToString();
  // Every pixel is finite and the holes were filled from the other views' segments.
  cv::Mat depth_ok = frame->depth_m == frame->depth_m;
  EXPECT_EQ(cv::countNonZero(depth_ok), kCamera.width * kCamera.height);
  std::printf("half the centre view's planes NaN: holes %.4f, PSNR %.2f dB\n",
              frame->holes.hole_ratio,
              MaskedPsnr(frame->bgr, views_[4].image));
  EXPECT_GT(MaskedPsnr(frame->bgr, views_[4].image), 25.0);
}

TEST_F(CpuSceneRendererTest, APlanePassingInfinityWithinItsRectangleIsDrawnFlatNotDropped) {
  std::vector<LayeredDepthView> layers = layers_;
  LayeredDepthView& centre = layers[4];
  // Tilt a segment of the centre view along u so that 1/z falls to 0 at the right edge of its
  // rectangle (its centre keeps its depth); another, mirrored, is behind infinity at its centre.
  const auto tilt = [&](int s, double zero_at_u) {
    DepthSegment& segment = centre.segments[s];
    const cv::Rect& b = segment.bbox;
    const double u = b.x + 0.5 * (b.width - 1), v = b.y + 0.5 * (b.height - 1);
    const double inverse = segment.inv_depth_a * u + segment.inv_depth_b * v + segment.inv_depth_c;
    segment.inv_depth_a = -inverse / (zero_at_u - u);
    segment.inv_depth_b = 0;
    segment.inv_depth_c = inverse - segment.inv_depth_a * u;
    return inverse;
  };
  int flat = -1, behind = -1;
  for (int s = 0; s < centre.NumSegments() && behind < 0; ++s) {
    if (centre.segments[s].bbox.width < 8) continue;
    (flat < 0 ? flat : behind) = s;
  }
  ASSERT_GE(behind, 0);
  const cv::Rect& b = centre.segments[flat].bbox;
  const double centre_inverse = tilt(flat, b.x + b.width);  // the rectangle's right edge
  tilt(behind, centre.segments[behind].bbox.x);             // its left edge, then beyond infinity at the centre
  centre.segments[behind].inv_depth_a *= -1;
  centre.segments[behind].inv_depth_c *= -1;
  StatusOr<render::LayeredScene> scene = render::LayeredScene::Create(views_, layers, RenderOptions());
  ASSERT_TRUE(scene.ok()) << scene.status().ToString();
  const render::SceneView& view = scene->views()[4];
  ASSERT_EQ(view.id, views_[4].id);
  EXPECT_TRUE(view.segments[flat].drawn);
  EXPECT_NEAR(view.segments[flat].plane[0], 0.0, 1e-12);
  EXPECT_NEAR(view.segments[flat].plane[1], 0.0, 1e-12);
  EXPECT_NEAR(view.segments[flat].plane[2], centre_inverse, 1e-9);
  EXPECT_FALSE(view.segments[behind].drawn);
  const auto warned = [&](const std::string& words) {
    return std::any_of(scene->warnings().begin(), scene->warnings().end(), [&](const std::string& w) {
      return w.find(words) != std::string::npos;
    });
  };
  EXPECT_TRUE(warned("1 segments drawn facing the camera"));
  EXPECT_TRUE(warned("1 segments dropped: plane at or behind infinity at the rectangle's centre"));
}

// A floor 10 cm below one view, a wall 5 m away: per output pixel covered by a source, the share
// the floor draws (depth under 2 m), from a camera at `height_m` below the view's (y down).
double FloorShare(double height_m) {
  View view;
  view.id.value = 0;
  view.camera = kCamera;
  view.cam_from_world = Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d::Zero());
  view.image.create(kCamera.height, kCamera.width, CV_8UC3);
  cv::RNG rng(7);
  rng.fill(view.image, cv::RNG::UNIFORM, 0, 255);
  DepthMap depth;
  depth.id = view.id;
  depth.depth_m.create(kCamera.height, kCamera.width, CV_32F);
  for (int v = 0; v < kCamera.height; ++v) {
    const double below = v - kCamera.cy;  // rays below the horizon meet the floor
    const float z = below > 0 ? static_cast<float>(std::min(5.0, 0.1 * kCamera.fy / below)) : 5.0f;
    depth.depth_m.row(v).setTo(z);
  }
  depth.confidence = cv::Mat(kCamera.height, kCamera.width, CV_32F, cv::Scalar(1));
  const std::vector<View> views = {view};
  LayeredFromDepthOptions planes;
  planes.jump_ratio = 1;  // one plane per block: the floor has no depth jump to split at
  const std::vector<LayeredDepthView> layers = {LayeredDepthFromDepthMap(view, depth, planes).value()};
  auto renderer = CpuSceneRenderer::Create(views, layers, RenderOptions());
  EXPECT_TRUE(renderer.ok()) << renderer.status().ToString();
  const FrameRender frame =
      (*renderer)
          ->Render(At(kCamera, Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, -height_m, 0))))
          .value();
  const cv::Mat floor = (frame.depth_m < 2.0f) & frame.coverage;
  return static_cast<double>(cv::countNonZero(floor)) / std::max(1, cv::countNonZero(frame.coverage));
}

// A surface is drawn only from the side its source saw it from: a camera that has gone under the
// floor does not see the floor's underside painted with its top (a ceiling of table top).
TEST(CpuSceneRendererBackFaceTest, ACameraBelowTheFloorDoesNotSeeItsTop) {
  const double above = FloorShare(-0.05), below = FloorShare(0.2);
  std::printf(
      "floor's share of the covered pixels: 5 cm above the view %.3f, 10 cm under the floor %.4f\n", above, below);
  EXPECT_GT(above, 0.2);
  EXPECT_LT(below, 0.01);
}

TEST_F(CpuSceneRendererTest, ACameraLookingAwayGivesAnEmptyFrameNotAnError) {
  auto renderer = Make();
  ASSERT_NE(renderer, nullptr);
  const Eigen::Quaterniond backwards(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()));
  for (RenderQuality quality : {RenderQuality::kPreview, RenderQuality::kOffline}) {
    RenderOptions options;
    options.quality = quality;
    auto r = Make(options);
    StatusOr<FrameRender> frame = r->Render(At(kCamera, Rigid3(backwards, Eigen::Vector3d::Zero())));
    ASSERT_TRUE(frame.ok()) << frame.status().ToString();
    EXPECT_EQ(frame->holes.hole_ratio, 1.0);
    EXPECT_GT(frame->holes.hole_score, 2.0);  // invalid for the direction stage
    EXPECT_EQ(cv::countNonZero(frame->coverage), 0);
  }
}

// Coverage() (full size and the coarse scene at 1/8) of a camera looking away, and of a 1x1
// camera: every pixel a hole, or a valid report; bad cameras are errors as for Render().
TEST_F(CpuSceneRendererTest, CoverageOfCamerasSeeingNothingIsAllHoles) {
  auto renderer = Make();
  ASSERT_NE(renderer, nullptr);
  const Rigid3 away(Eigen::Quaterniond(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY())), Eigen::Vector3d::Zero());
  for (const CameraModel& camera : {kCamera, kCamera.Scaled(0.125)}) {
    StatusOr<CoverageReport> report = renderer->Coverage(camera, away);
    ASSERT_TRUE(report.ok()) << report.status().ToString();
    EXPECT_EQ(report->hole_ratio, 1.0) << camera.width;
    EXPECT_GT(report->hole_score, 2.0) << camera.width;  // invalid for the direction stage
  }
  CameraModel one = CameraModel::Pinhole(1, 1, 1.0);
  StatusOr<CoverageReport> tiny = renderer->Coverage(one, views_[4].cam_from_world);
  ASSERT_TRUE(tiny.ok()) << tiny.status().ToString();
  EXPECT_EQ(tiny->width, 1);
  EXPECT_TRUE(tiny->hole_ratio == 0.0 || tiny->hole_ratio == 1.0);
  CameraModel nan_focal = kCamera;
  nan_focal.fx = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(renderer->Coverage(nan_focal, views_[4].cam_from_world).ok());
  EXPECT_FALSE(renderer->Render(At(nan_focal, views_[4].cam_from_world)).ok());
}

TEST_F(CpuSceneRendererTest, BadCamerasAreErrorsThatNameTheProblem) {
  auto renderer = Make();
  ASSERT_NE(renderer, nullptr);
  const Rigid3 pose = views_[4].cam_from_world;
  CameraModel zero = kCamera;
  zero.width = 0;
  StatusOr<FrameRender> frame = renderer->Render(At(zero, pose));
  ASSERT_FALSE(frame.ok());
  EXPECT_NE(frame.status().message().find("0x240"), std::string::npos) << frame.status().ToString();
  EXPECT_FALSE(renderer->Coverage(zero, pose).ok());
  Rigid3 nan_pose = pose;
  nan_pose.translation.x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(renderer->Render(At(kCamera, nan_pose)).ok());
  RenderOptions small;
  small.max_output_pixels = 1000;
  auto capped = Make(small);
  frame = capped->Render(At(kCamera, pose));
  ASSERT_FALSE(frame.ok());
  EXPECT_NE(frame.status().message().find("max_output_pixels"), std::string::npos) << frame.status().ToString();
  // Layered depth that does not match its view: named.
  std::vector<LayeredDepthView> layers = layers_;
  layers[3].layers[1].weight = cv::Mat(10, 10, CV_32F, cv::Scalar(0));
  auto mismatched = CpuSceneRenderer::Create(views_, layers, RenderOptions());
  ASSERT_FALSE(mismatched.ok());
  EXPECT_NE(mismatched.status().message().find("layer 1 weight"), std::string::npos) << mismatched.status().ToString();
}

}  // namespace
}  // namespace px
