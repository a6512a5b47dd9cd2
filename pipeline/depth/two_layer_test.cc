// The two-layer split at a synthetic foreground/background boundary, and robust plane fits.
#include "pipeline/depth/two_layer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <opencv2/imgproc.hpp>
#include <random>

#include "pipeline/core/layered_depth.h"
#include "pipeline/depth/pixel_depth_near_planes.h"
#include "pipeline/depth/segment_planes.h"
#include "pipeline/depth/superpixels.h"

namespace px::depth {
namespace {

// Left half: a red foreground segment at 1 m; right half: a blue background at 3 m.
struct EdgeScene {
  CameraModel camera = CameraModel::Pinhole(64, 32, 60.0);
  cv::Mat bgr;
  SegmentImage segments;
};

EdgeScene MakeEdgeScene(double background_depth_m) {
  EdgeScene scene;
  scene.bgr = cv::Mat(32, 64, CV_8UC3, cv::Scalar(255, 0, 0));
  scene.bgr.colRange(0, 32).setTo(cv::Scalar(0, 0, 255));
  scene.segments.labels = cv::Mat(32, 64, CV_32S, cv::Scalar(1));
  scene.segments.labels.colRange(0, 32).setTo(0);
  InversePlane front, back;
  front.c = 1.0;
  back.c = 1.0 / background_depth_m;
  scene.segments.planes = {front, back};
  scene.segments.confidence = {0.9f, 0.8f};
  return scene;
}

TwoLayerOptions EdgeOptions() {
  TwoLayerOptions options;
  options.edge_inverse_depth_m = 0.05;
  options.band_radius_px = 3;
  options.min_inverse_depth_m = 0.01;
  return options;
}

TEST(TwoLayerTest, SoftAlphaAcrossADepthEdge) {
  const EdgeScene scene = MakeEdgeScene(3.0);
  const LayeredDepthView view = BuildTwoLayerView(
      ViewId{7}, scene.camera, scene.bgr, scene.segments, cv::Mat(32, 64, CV_32F, cv::Scalar(0.7f)), EdgeOptions());
  ASSERT_TRUE(ValidateLayeredDepthView(view).ok()) << ValidateLayeredDepthView(view).ToString();
  EXPECT_EQ(view.id.value, 7);
  ASSERT_EQ(view.NumSegments(), 2);
  for (int y = 0; y < 32; ++y) {
    float previous = 2;
    for (int x = 0; x < 64; ++x) {
      const float w0 = view.layers[0].weight.at<float>(y, x), w1 = view.layers[1].weight.at<float>(y, x);
      EXPECT_NEAR(w0 + w1, 1.0f, 1e-5f);
      // The foreground's share: its layer-0 weight where layer 0 is the foreground, else 0.
      const float front = view.layers[0].segment.at<int32_t>(y, x) == 0 ? w0 : 0.0f;
      EXPECT_LE(front, previous + 1e-6f) << "alpha rises at x = " << x;
      previous = front;
    }
  }
  const int y = 16;
  // Deep inside either side: one layer only.
  EXPECT_EQ(view.layers[0].weight.at<float>(y, 5), 1.0f);
  EXPECT_EQ(view.layers[1].segment.at<int32_t>(y, 5), SegmentLayer::kNoSegment);
  EXPECT_EQ(view.layers[0].segment.at<int32_t>(y, 60), 1);
  // The band: the foreground in front, the background behind it, each in its own colour (no
  // mixing: red in front, blue behind on both sides of the edge). The edge is sharp in the
  // image, so the matte is too: pure red pixels are all foreground, pure blue ones background.
  for (int x = 29; x <= 34; ++x) {
    EXPECT_EQ(view.layers[0].segment.at<int32_t>(y, x), 0) << x;
    EXPECT_EQ(view.layers[1].segment.at<int32_t>(y, x), 1) << x;
    EXPECT_EQ(view.layers[0].weight.at<float>(y, x), x < 32 ? 1.0f : 0.0f) << x;
    EXPECT_EQ(view.layers[0].colour.at<cv::Vec3b>(y, x), cv::Vec3b(0, 0, 255)) << x;
    EXPECT_EQ(view.layers[1].colour.at<cv::Vec3b>(y, x), cv::Vec3b(255, 0, 0)) << x;
  }
  // Depth follows the dominant layer.
  EXPECT_NEAR(view.depth_m.at<float>(y, 31), 1.0f, 1e-5f);
  EXPECT_NEAR(view.depth_m.at<float>(y, 32), 3.0f, 1e-5f);
  EXPECT_FLOAT_EQ(view.segments[0].confidence, 0.9f);
}

TEST(TwoLayerTest, MixedPixelsGetTheAlphaTheirColourSays) {
  // An anti-aliased silhouette: column 32 a 30/70 mix of red and blue, the segment border one
  // pixel off the real edge (column 32 labelled foreground).
  EdgeScene scene = MakeEdgeScene(3.0);
  scene.bgr.col(32).setTo(cv::Scalar(0.7 * 255, 0, 0.3 * 255));
  scene.segments.labels.col(32).setTo(0);
  const LayeredDepthView view = BuildTwoLayerView(
      ViewId{1}, scene.camera, scene.bgr, scene.segments, cv::Mat(32, 64, CV_32F, cv::Scalar(1.0f)), EdgeOptions());
  ASSERT_TRUE(ValidateLayeredDepthView(view).ok()) << ValidateLayeredDepthView(view).ToString();
  const int y = 10;
  EXPECT_NEAR(view.layers[0].weight.at<float>(y, 32), 0.3f, 0.01f);
  EXPECT_NEAR(view.layers[1].weight.at<float>(y, 32), 0.7f, 0.01f);
  EXPECT_NEAR(view.depth_m.at<float>(y, 32), 3.0f, 1e-5f);  // mostly background
  EXPECT_EQ(view.layers[0].weight.at<float>(y, 31), 1.0f);
  EXPECT_EQ(view.layers[0].weight.at<float>(y, 33), 0.0f);
  // Where the two sides look alike the colour cannot tell: the linear ramp stays.
  EdgeScene alike = MakeEdgeScene(3.0);
  alike.bgr.setTo(cv::Scalar(100, 100, 100));
  alike.bgr.colRange(0, 32).setTo(cv::Scalar(104, 100, 100));
  const LayeredDepthView ramp = BuildTwoLayerView(
      ViewId{2}, alike.camera, alike.bgr, alike.segments, cv::Mat(32, 64, CV_32F, cv::Scalar(1.0f)), EdgeOptions());
  for (int x = 29; x <= 34; ++x) {
    EXPECT_GT(ramp.layers[0].weight.at<float>(y, x), 0.0f) << x;
    EXPECT_LT(ramp.layers[0].weight.at<float>(y, x), 1.0f) << x;
  }
  EXPECT_GT(ramp.layers[0].weight.at<float>(y, 31), 0.5f);
  EXPECT_LT(ramp.layers[0].weight.at<float>(y, 32), 0.5f);
  EXPECT_EQ(CountBoundaryPixels(ramp), 6 * 32);
}

TEST(TwoLayerTest, NoBandWhereNeighbouringPlanesAgree) {
  const EdgeScene scene = MakeEdgeScene(1.01);  // inverse depth jump 0.0099 < 0.05
  const LayeredDepthView view = BuildTwoLayerView(
      ViewId{0}, scene.camera, scene.bgr, scene.segments, cv::Mat(32, 64, CV_32F, cv::Scalar(0.7f)), EdgeOptions());
  ASSERT_TRUE(ValidateLayeredDepthView(view).ok());
  EXPECT_EQ(CountBoundaryPixels(view), 0);
  EXPECT_EQ(view.layers[0].segment.at<int32_t>(3, 31), 0);
  EXPECT_EQ(view.layers[0].segment.at<int32_t>(3, 32), 1);
}

TEST(PixelDepthNearPlanesTest, KeepsPixelDepthNearThePlaneOutsideTheBands) {
  const EdgeScene scene = MakeEdgeScene(3.0);
  LayeredDepthView view = BuildTwoLayerView(
      ViewId{0}, scene.camera, scene.bgr, scene.segments, cv::Mat(32, 64, CV_32F, cv::Scalar(0.7f)), EdgeOptions());
  // The matcher saw relief on both planes (inverse depth off by up to +-0.02), an outlier far
  // off the front plane and a pixel without depth.
  cv::Mat inverse_depth(32, 64, CV_32F);
  for (int y = 0; y < 32; ++y) {
    for (int x = 0; x < 64; ++x) {
      const float plane = x < 32 ? 1.0f : 1.0f / 3.0f;
      inverse_depth.at<float>(y, x) = plane + 0.02f * std::sin(0.3f * static_cast<float>(x + y));
    }
  }
  inverse_depth.at<float>(10, 5) = 0.5f;  // 2 m: an outlier, 0.5 off the plane
  inverse_depth.at<float>(3, 3) = 0;      // no depth there
  const int changed = KeepPixelDepthNearPlanes(inverse_depth, 0.05, &view);
  ASSERT_TRUE(ValidateLayeredDepthView(view).ok());
  EXPECT_EQ(changed, 64 * 32 - 6 * 32 - 2);  // all but the band (x 29..34), the outlier and (3, 3)
  EXPECT_NEAR(view.depth_m.at<float>(20, 7), 1.0f / inverse_depth.at<float>(20, 7), 1e-5f);
  EXPECT_NEAR(view.depth_m.at<float>(20, 50), 1.0f / inverse_depth.at<float>(20, 50), 1e-5f);
  EXPECT_NE(view.depth_m.at<float>(20, 50), 3.0f);
  EXPECT_NEAR(view.depth_m.at<float>(10, 5), 1.0f, 1e-5f);  // the outlier takes the plane
  EXPECT_NEAR(view.depth_m.at<float>(3, 3), 1.0f, 1e-5f);
  EXPECT_NEAR(view.depth_m.at<float>(10, 31), 1.0f, 1e-5f);  // band: the dominant layer's plane
  EXPECT_NEAR(view.depth_m.at<float>(10, 33), 3.0f, 1e-5f);
  // The segments the renderer draws keep their planes.
  EXPECT_DOUBLE_EQ(view.segments[0].inv_depth_c, 1.0);
  EXPECT_DOUBLE_EQ(view.segments[1].inv_depth_c, 1.0 / 3.0);
}

TEST(TwoLayerTest, PlanesBehindTheCameraBecomeFrontoParallel) {
  EdgeScene scene = MakeEdgeScene(3.0);
  scene.segments.planes[1].a = -0.05;  // 1/z reaches 0 at x ~ 6.7, well inside the bbox
  scene.segments.planes[1].c = 1.0 / 3.0 + 0.05 * 40;
  const LayeredDepthView view = BuildTwoLayerView(
      ViewId{0}, scene.camera, scene.bgr, scene.segments, cv::Mat(32, 64, CV_32F, cv::Scalar(0.7f)), EdgeOptions());
  ASSERT_TRUE(ValidateLayeredDepthView(view).ok()) << ValidateLayeredDepthView(view).ToString();
  EXPECT_EQ(view.segments[1].inv_depth_a, 0.0);
}

TEST(SegmentPlanesTest, RansacRecoversASlantedPlaneDespiteOutliers) {
  // One segment covering a 40x30 image; u = 0.002 x - 0.001 y + 0.5, a quarter of it wrong.
  Superpixels segments;
  segments.labels = cv::Mat::zeros(30, 40, CV_32S);
  segments.count = 1;
  segments.sizes = {1200};
  cv::Mat u(30, 40, CV_32F), weight(30, 40, CV_32F, cv::Scalar(1.0f));
  std::mt19937 random(3);
  std::uniform_real_distribution<float> noise(-0.2f, 0.2f);
  for (int y = 0; y < 30; ++y) {
    for (int x = 0; x < 40; ++x) {
      u.at<float>(y, x) = static_cast<float>(0.002 * x - 0.001 * y + 0.5);
      if ((x * 7 + y * 3) % 4 == 0) u.at<float>(y, x) += noise(random) + (noise(random) > 0 ? 0.1f : -0.1f);
    }
  }
  weight.at<float>(0, 0) = 0.0f;  // below min_weight: unused
  PlaneFitOptions options;
  options.inlier_tolerance = 0.002;
  const std::vector<SegmentPlane> planes = FitSegmentPlanes(segments, u, weight, options);
  ASSERT_EQ(planes.size(), 1u);
  EXPECT_EQ(planes[0].source, PlaneSource::kFitted);
  EXPECT_NEAR(planes[0].plane.a, 0.002, 1e-4);
  EXPECT_NEAR(planes[0].plane.b, -0.001, 1e-4);
  EXPECT_NEAR(planes[0].plane.At(20, 15), 0.525, 1e-3);
  EXPECT_NEAR(planes[0].support, 0.75, 0.03);
}

TEST(SegmentPlanesTest, TooFewConfidentPixelsLeaveTheSegmentUnfitted) {
  Superpixels segments;
  segments.labels = cv::Mat::zeros(10, 10, CV_32S);
  segments.count = 1;
  segments.sizes = {100};
  const cv::Mat u(10, 10, CV_32F, cv::Scalar(0.5f)), weight(10, 10, CV_32F, cv::Scalar(0.05f));
  PlaneFitOptions options;
  options.inlier_tolerance = 0.01;
  EXPECT_EQ(FitSegmentPlanes(segments, u, weight, options)[0].source, PlaneSource::kNone);
}

TEST(SuperpixelsTest, UpsampledLabelsFollowTheFullResolutionEdge) {
  // A vertical colour edge at x = 33 of a 64-wide view: at half resolution it falls inside a
  // working pixel; the upsampled labels put it back on the full-resolution edge.
  cv::Mat bgr(32, 64, CV_8UC3, cv::Scalar(40, 200, 40));
  bgr.colRange(33, 64).setTo(cv::Scalar(200, 40, 200));
  cv::Mat small;
  cv::resize(bgr, small, cv::Size(32, 16), 0, 0, cv::INTER_AREA);
  const Superpixels segments = Oversegment(small, 8, 10.0f, 5);
  const cv::Mat labels = UpsampleLabels(segments, bgr, 0.5);
  ASSERT_EQ(labels.size(), bgr.size());
  cv::Mat lab;
  cv::cvtColor(bgr, lab, cv::COLOR_BGR2Lab);
  const cv::Vec3f green = lab.at<cv::Vec3b>(0, 0), purple = lab.at<cv::Vec3b>(0, 63);
  for (int y = 0; y < 32; ++y) {
    for (int x = 30; x <= 35; ++x) {
      const cv::Vec3f mean = segments.mean_lab[labels.at<int>(y, x)];
      const bool looks_green = cv::norm(mean - green) < cv::norm(mean - purple);
      EXPECT_EQ(looks_green, x < 33) << "(" << x << ", " << y << ")";
    }
  }
}

}  // namespace
}  // namespace px::depth
