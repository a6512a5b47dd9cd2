#include "pipeline/render/hole_views.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "pipeline/render/cpu_scene_renderer.h"
#include "pipeline/render/render_test_util.h"

namespace px::render {
namespace {

// A 3x3 lattice 30 cm apart (the background, 3 m away, moves 14 px between columns) and a camera
// near the centre lens turned 4 degrees to the left: the strip at its left edge lies outside the
// three views the view mesh blends there, but the left column saw most of it.
class HoleViewsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    testing::MakeLayeredLattice(scene_, 3, 3, kBaselineM, kCamera, &views_, &layers_);
    const Eigen::Vector3d centre(0.05, 0.02, 0.0);
    const Eigen::Quaterniond turned(Eigen::AngleAxisd(4.0 * M_PI / 180, Eigen::Vector3d::UnitY()));
    camera_.camera = kCamera;
    camera_.cam_from_world = Rigid3(turned, -(turned * centre));
    cv::Mat truth_depth;
    scene_.Render(kCamera, camera_.cam_from_world, &truth_, &truth_depth);
  }

  FrameRender RenderWith(bool other_views, RenderQuality quality, CpuFrameStats* stats) {
    RenderOptions options;
    options.quality = quality;
    options.holes_from_other_views = other_views;
    auto renderer = CpuSceneRenderer::Create(views_, layers_, options);
    EXPECT_TRUE(renderer.ok()) << renderer.status().ToString();
    auto frame = (*renderer)->Render(camera_);
    EXPECT_TRUE(frame.ok()) << frame.status().ToString();
    *stats = (*renderer)->last_frame();
    return *frame;
  }

  static constexpr double kBaselineM = 0.3;
  const CameraModel kCamera = CameraModel::Pinhole(160, 120, 140);
  testing::PlaneScene scene_;
  std::vector<View> views_;
  std::vector<LayeredDepthView> layers_;
  VirtualCamera camera_;
  cv::Mat truth_;
};

TEST_F(HoleViewsTest, SlotsNameOnlyOtherViewsThatSeeTheHoles) {
  RenderOptions options;
  auto scene = LayeredScene::Create(views_, layers_, options);
  ASSERT_TRUE(scene.ok()) << scene.status().ToString();
  std::vector<ViewSlots> slots;
  scene->mesh().ComputeWeights(kCamera, camera_.cam_from_world, &slots);
  // Holes: the 12 leftmost columns, and one pixel in the middle.
  cv::Mat holes = cv::Mat::zeros(kCamera.height, kCamera.width, CV_8U);
  holes.colRange(0, 12).setTo(255);
  holes.at<uint8_t>(60, 80) = 255;
  const cv::Rect crop(0, 0, 81, kCamera.height);
  const std::vector<ViewSlots> other = OtherViewSlots(*scene, kCamera, camera_.cam_from_world, slots, holes, crop);
  ASSERT_EQ(other.size(), static_cast<size_t>(crop.area()));
  int assigned = 0;
  for (int y = 0; y < crop.height; ++y) {
    for (int x = 0; x < crop.width; ++x) {
      const ViewSlots& s = other[static_cast<size_t>(y) * crop.width + x];
      if (holes.at<uint8_t>(y, x) == 0) {
        EXPECT_EQ(s.view[0], ViewSlots::kNone) << "no hole at " << x << ", " << y;
        continue;
      }
      float sum = 0;
      for (int k = 0; k < 3; ++k) {
        if (s.view[k] == ViewSlots::kNone) continue;
        const ViewSlots& own = slots[static_cast<size_t>(y) * kCamera.width + x];
        for (int j = 0; j < 3; ++j) EXPECT_NE(s.view[k], own.view[j]) << "a blended view again at " << x << ", " << y;
        sum += s.weight[k];
      }
      if (s.view[0] != ViewSlots::kNone) {
        ++assigned;
        EXPECT_NEAR(sum, 1.0f, 1e-5f);
      }
    }
  }
  EXPECT_GT(assigned, 12 * kCamera.height / 2);
}

// The other views draw most of the strip, and far closer to the truth than filling it from its
// border; coverage (before hole filling) and H(V) do not change.
TEST_F(HoleViewsTest, OtherViewsCoverTheStripCloseToTheTruth) {
  for (RenderQuality quality : {RenderQuality::kPreview, RenderQuality::kOffline}) {
    SCOPED_TRACE(std::string(RenderQualityName(quality)));
    CpuFrameStats off_stats, on_stats;
    const FrameRender off = RenderWith(false, quality, &off_stats);
    const FrameRender on = RenderWith(true, quality, &on_stats);
    const cv::Mat holes = off.coverage == 0;
    ASSERT_GT(cv::countNonZero(holes), kCamera.height * 5) << "the turned camera must leave a strip uncovered";
    EXPECT_EQ(off_stats.other_view_pixels, 0);
    EXPECT_GT(on_stats.other_view_pixels, cv::countNonZero(holes) / 2);
    EXPECT_EQ(cv::countNonZero(on.coverage != off.coverage), 0);
    EXPECT_DOUBLE_EQ(on.holes.hole_score, off.holes.hole_score);
    const double psnr_off = testing::MaskedPsnr(off.bgr, truth_, holes);
    const double psnr_on = testing::MaskedPsnr(on.bgr, truth_, holes);
    std::printf("%s: holes %d px, %d from other views; PSNR over them %.2f dB filled, %.2f dB other views\n",
                std::string(RenderQualityName(quality)).c_str(),
                cv::countNonZero(holes),
                on_stats.other_view_pixels,
                psnr_off,
                psnr_on);
    EXPECT_GT(psnr_on, psnr_off + 5.0);
    EXPECT_GT(psnr_on, 30.0);
    // Pixels the blended views covered are untouched.
    cv::Mat same;
    cv::compare(on.bgr, off.bgr, same, cv::CMP_EQ);
    cv::cvtColor(same, same, cv::COLOR_BGR2GRAY);
    EXPECT_EQ(cv::countNonZero((same != 255) & off.coverage), 0);
  }
}

// Without the other views the strip is a hole at the frame's border. Carried straight out
// (border_holes.h, spread 0) each of its rows holds the colour of the row's first covered pixel;
// the pixels covered before filling are untouched.
TEST_F(HoleViewsTest, BorderHolesCarryTheStripsInnerEdgeOut) {
  for (RenderQuality quality : {RenderQuality::kPreview, RenderQuality::kOffline}) {
    SCOPED_TRACE(std::string(RenderQualityName(quality)));
    RenderOptions options;
    options.quality = quality;
    options.holes_from_other_views = false;
    options.border_holes.spread = 0;
    auto renderer = CpuSceneRenderer::Create(views_, layers_, options);
    ASSERT_TRUE(renderer.ok()) << renderer.status().ToString();
    const auto frame = (*renderer)->Render(camera_);
    ASSERT_TRUE(frame.ok()) << frame.status().ToString();
    ASSERT_GT(cv::countNonZero(frame->coverage == 0), kCamera.height * 5) << "the turned camera must leave a strip";
    int rows_carried = 0;
    for (int y = 0; y < kCamera.height; ++y) {
      int edge = 0;
      while (edge < kCamera.width && frame->coverage.at<uint8_t>(y, edge) == 0) ++edge;
      ASSERT_GT(edge, 2) << "row " << y << " has no strip";
      const cv::Vec3b inner = frame->bgr.at<cv::Vec3b>(y, edge);
      bool same = true;
      for (int x = 0; x < edge - 1; ++x)
        same = same && cv::norm(frame->bgr.at<cv::Vec3b>(y, x), inner, cv::NORM_INF) <= 1;
      rows_carried += same ? 1 : 0;
    }
    // A row whose strip ends in a soft edge keeps that pixel's own share of colour.
    EXPECT_GT(rows_carried, kCamera.height * 9 / 10);
  }
}

// LargeHoles keeps the holes the 7x7 first pass cannot close whole, with their box: a 5x5 hole
// goes to the fill, a 12x12 one stays (whole, as SmallHoles keeps whole holes), and radius 0
// keeps every hole.
TEST(LargeHolesTest, KeepsOnlyHolesTheFirstFillPassCannotClose) {
  cv::Mat known(60, 80, CV_8U, cv::Scalar(255));
  known(cv::Rect(5, 5, 5, 5)).setTo(0);
  cv::Mat holes;
  EXPECT_TRUE(LargeHoles(known, 3, &holes).empty());
  EXPECT_EQ(LargeHoles(known, 0, &holes), cv::Rect(5, 5, 5, 5));
  known(cv::Rect(40, 30, 12, 12)).setTo(0);
  EXPECT_EQ(LargeHoles(known, 3, &holes), cv::Rect(40, 30, 12, 12));
  EXPECT_EQ(cv::countNonZero(holes), 144);
}

}  // namespace
}  // namespace px::render
