// Colour effects, depth of field and exemplar inpainting: the frame passes after compositing.
#include <gtest/gtest.h>

#include <cmath>

#include "pipeline/render/color_effects.h"
#include "pipeline/render/depth_of_field.h"
#include "pipeline/render/exemplar_inpaint.h"
#include "pipeline/render/soft_z.h"

namespace px::render {
namespace {

ColorEffect Box(ColorEffectKind kind, double amount, bool invert = false) {
  ColorEffect effect;
  effect.kind = kind;
  effect.amount = amount;
  effect.region_min_in_world = Eigen::Vector3d(-0.1, -0.1, 0.9);
  effect.region_max_in_world = Eigen::Vector3d(0.1, 0.1, 1.1);
  effect.falloff_m = 0.05;
  effect.invert = invert;
  return effect;
}

TEST(ColorEffectsTest, StrengthIsOneInsideAndFallsOffAsAGaussian) {
  const ColorEffect effect = Box(ColorEffectKind::kBrightness, 0.5);
  EXPECT_DOUBLE_EQ(EffectStrength(effect, Eigen::Vector3d(0, 0, 1)), 1.0);
  EXPECT_DOUBLE_EQ(EffectStrength(effect, Eigen::Vector3d(0.1, 0.1, 1.1)), 1.0);  // on the box
  for (double d : {0.01, 0.05, 0.1, 0.2}) {
    EXPECT_NEAR(EffectStrength(effect, Eigen::Vector3d(0.1 + d, 0, 1)), std::exp(-d * d / (2 * 0.05 * 0.05)), 1e-12);
  }
  const ColorEffect inverted = Box(ColorEffectKind::kBrightness, 0.5, true);
  EXPECT_DOUBLE_EQ(EffectStrength(inverted, Eigen::Vector3d(0, 0, 1)), 0.0);
  EXPECT_NEAR(EffectStrength(inverted, Eigen::Vector3d(0.15, 0, 1)), 1 - std::exp(-0.5), 1e-12);
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_DOUBLE_EQ(EffectStrength(effect, Eigen::Vector3d(inf, inf, inf)), 0.0);
}

TEST(ColorEffectsTest, AppliesToTheRegionSeenThroughTheCamera) {
  // A 1 m deep wall seen head on: the box covers x in [-0.1, 0.1] m, i.e. +-10 px at f = 100.
  const CameraModel camera = CameraModel::Pinhole(101, 21, 100);
  cv::Mat depth(21, 101, CV_32F, cv::Scalar(1.0f));
  cv::Mat colour(21, 101, CV_32FC3, cv::Scalar(200, 100, 50));
  const Rigid3 identity;
  ApplyColorEffects({Box(ColorEffectKind::kSaturation, 0.0)}, camera, identity, depth, &colour);
  const float luma = 0.114f * 200 + 0.587f * 100 + 0.299f * 50;
  const cv::Vec3f centre = colour.at<cv::Vec3f>(10, 50);
  EXPECT_NEAR(centre[0], luma, 1e-3);  // grey inside
  EXPECT_NEAR(centre[2], luma, 1e-3);
  // 10 cm past the box (pixel 70 sees x = 0.2 m): exp(-2) of the effect.
  const cv::Vec3f outside = colour.at<cv::Vec3f>(10, 70);
  const float s = std::exp(-2.0f);
  EXPECT_NEAR(outside[0], (1 - s) * 200 + s * luma, 0.05);
  // Where nothing is (depth 0), nothing changes.
  depth.setTo(0.0f);
  cv::Mat untouched(21, 101, CV_32FC3, cv::Scalar(200, 100, 50));
  ApplyColorEffects({Box(ColorEffectKind::kBrightness, 0.0)}, camera, identity, depth, &untouched);
  EXPECT_EQ(untouched.at<cv::Vec3f>(10, 50), cv::Vec3f(200, 100, 50));
}

// Gradient energy (sum of squared horizontal differences) of column band [x0, x1).
double Sharpness(const cv::Mat& colour, int x0, int x1) {
  double energy = 0;
  for (int y = 0; y < colour.rows; ++y) {
    for (int x = x0; x + 1 < x1; ++x) {
      const cv::Vec3f d = colour.at<cv::Vec3f>(y, x + 1) - colour.at<cv::Vec3f>(y, x);
      energy += d.dot(d);
    }
  }
  return energy;
}

TEST(DepthOfFieldTest, CircleOfConfusionIsThinLens) {
  EXPECT_DOUBLE_EQ(CircleOfConfusionPx(0.01, 2.0, 500, 2.0), 0.0);
  EXPECT_NEAR(CircleOfConfusionPx(0.01, 2.0, 500, 1.0), 0.01 * 500 * 0.5, 1e-12);
  EXPECT_NEAR(CircleOfConfusionPx(0.01, 2.0, 500, 4.0), 0.01 * 500 * 0.25, 1e-12);
  EXPECT_EQ(CircleOfConfusionPx(0.0, 2.0, 500, 4.0), 0.0);
}

TEST(DepthOfFieldTest, FocusPlaneStaysSharpAndTheRestBlursWithItsCircle) {
  // A checkerboard of 4 px squares; the left third at the focus depth (2 m), the middle at 1 m
  // (circle 10 px at f 500, 4 cm aperture... ) and the right third at 8 m.
  const int width = 180, height = 60;
  cv::Mat colour(height, width, CV_32FC3);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const float v = ((x / 4 + y / 4) % 2) ? 220.0f : 30.0f;
      colour.at<cv::Vec3f>(y, x) = cv::Vec3f(v, v, v);
    }
  }
  cv::Mat depth(height, width, CV_32F, cv::Scalar(2.0f));
  depth(cv::Rect(60, 0, 60, height)).setTo(1.0f);
  depth(cv::Rect(120, 0, 60, height)).setTo(8.0f);
  const cv::Mat original = colour.clone();
  const double aperture_m = 0.02, focus_m = 2.0, focal_px = 500;
  // Circles: 0 at 2 m, 5 px at 1 m, 3.75 px at 8 m.
  const DepthOfFieldReport report = ApplyPreviewDepthOfField(aperture_m, focus_m, focal_px, depth, &colour);
  EXPECT_GT(report.levels, 0);
  // Away from the bands' borders: the focus band is untouched, the others lose most of the
  // checkerboard's edges, the nearer (larger circle) more than the farther.
  cv::Mat diff;
  cv::absdiff(colour(cv::Rect(0, 0, 50, height)), original(cv::Rect(0, 0, 50, height)), diff);
  EXPECT_LE(cv::norm(diff, cv::NORM_INF), 1e-3);
  const double sharp = Sharpness(original, 70, 110);
  const double near_band = Sharpness(colour, 70, 110), far_band = Sharpness(colour, 130, 170);
  std::printf("sharpness: focus %.0f, near %.0f, far %.0f\n", Sharpness(colour, 5, 45), near_band, far_band);
  EXPECT_LT(near_band, 0.2 * sharp);
  EXPECT_LT(far_band, 0.5 * sharp);
  EXPECT_LT(near_band, far_band);
  // The blurred foreground spills over the sharp background beside it (silhouette correction).
  EXPECT_GT(report.silhouette_pixels, 0);
  cv::absdiff(colour(cv::Rect(57, 0, 3, height)), original(cv::Rect(57, 0, 3, height)), diff);
  EXPECT_GT(cv::norm(diff, cv::NORM_INF), 5.0);
}

TEST(DepthOfFieldTest, ApertureViewpointsStayRegisteredOnTheFocalPlane) {
  const CameraModel camera = CameraModel::Pinhole(64, 48, 50);
  const Rigid3 pose;
  const auto viewpoints = ApertureViewpoints(camera, pose, 0.02, 2.0, 16);
  ASSERT_EQ(viewpoints.size(), 16u);
  const Eigen::Vector3d on_focus(0.1, -0.05, 2.0), off_focus(0.1, -0.05, 1.0);
  double spread_off = 0;
  for (const ApertureViewpoint& v : viewpoints) {
    const Eigen::Vector3d centre = CameraCentre(v.cam_from_world);
    EXPECT_LE(centre.norm(), 0.01 + 1e-12);  // inside the aperture disc
    const Eigen::Vector3d p = v.cam_from_world * on_focus, q = v.cam_from_world * off_focus;
    const double x = v.camera.fx * p.x() / p.z() + v.camera.cx;
    EXPECT_NEAR(x, camera.fx * 0.1 / 2.0 + camera.cx, 1e-9);
    spread_off =
        std::max(spread_off, std::abs(v.camera.fx * q.x() / q.z() + v.camera.cx - (camera.fx * 0.1 + camera.cx)));
  }
  EXPECT_GT(spread_off, 0.1);  // off the focal plane, the viewpoints disagree: that is the blur
}

TEST(ExemplarInpaintTest, FillsADisocclusionFromTheBackgroundSide) {
  // Near red surface (1 m) on the left, a 24 px hole, and far textured background (3 m, blue
  // stripes) on the right: the hole opened behind the foreground must take the background.
  const int width = 100, height = 40;
  cv::Mat colour(height, width, CV_32FC3), depth(height, width, CV_32F);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const bool near_side = x < 30;
      colour.at<cv::Vec3f>(y, x) = near_side ? cv::Vec3f(0, 0, 230) : cv::Vec3f((y / 3) % 2 ? 240 : 160, 20, 0);
      depth.at<float>(y, x) = near_side ? 1.0f : 3.0f;
    }
  }
  cv::Mat known(height, width, CV_8U, cv::Scalar(255));
  known(cv::Rect(30, 0, 24, height)).setTo(0);
  colour.setTo(cv::Scalar(0, 0, 0), known == 0);
  depth.setTo(0.0f, known == 0);
  const cv::Mat target = known == 0;
  const SoftZ soft_z(2.0, 0.1);
  const InpaintReport report = InpaintDepthAware(soft_z, InpaintOptions(), target, &known, &colour, &depth);
  EXPECT_EQ(report.pixels, 24 * height);
  EXPECT_EQ(report.components, 1);
  EXPECT_EQ(report.two_layer_components, 1);
  EXPECT_EQ(cv::countNonZero(known), width * height);
  int background = 0;
  for (int y = 0; y < height; ++y) {
    for (int x = 30; x < 54; ++x) {
      const cv::Vec3f c = colour.at<cv::Vec3f>(y, x);
      background += (c[0] > 100 && c[2] < 50) ? 1 : 0;
      ASSERT_NEAR(depth.at<float>(y, x), 3.0f, 0.3f) << x << "," << y;
    }
  }
  // Every filled pixel is background-coloured (no red foreground smeared into the hole).
  EXPECT_EQ(background, 24 * height);
}

// A hole along the image's left border (a camera turned past every source's field of view) is
// left for the reverse soft z smear when fill_border_holes is false; a hole inside is still filled.
TEST(ExemplarInpaintTest, LeavesHolesAtTheImageBorderWhenAsked) {
  const int width = 80, height = 40;
  cv::Mat colour(height, width, CV_32FC3, cv::Scalar(40, 120, 200)), depth(height, width, CV_32F, cv::Scalar(2.0f));
  cv::Mat known(height, width, CV_8U, cv::Scalar(255));
  known(cv::Rect(0, 0, 10, height)).setTo(0);  // border strip
  known(cv::Rect(40, 15, 12, 12)).setTo(0);    // interior hole
  const cv::Mat target = known == 0;
  InpaintOptions options;
  options.fill_border_holes = false;
  const InpaintReport report = InpaintDepthAware(SoftZ(2.0, 0.1), options, target, &known, &colour, &depth);
  EXPECT_EQ(report.border_components, 1);
  EXPECT_EQ(report.components, 1);
  EXPECT_EQ(report.pixels, 12 * 12);
  EXPECT_EQ(cv::countNonZero(known(cv::Rect(0, 0, 10, height))), 0);
  EXPECT_EQ(cv::countNonZero(known(cv::Rect(40, 15, 12, 12))), 12 * 12);
}

}  // namespace
}  // namespace px::render
