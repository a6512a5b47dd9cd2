#include "pipeline/render/seam_planes.h"

#include <gtest/gtest.h>

#include "pipeline/render/seam_test_util.h"

namespace px::render {
namespace {

const CameraModel kCamera = CameraModel::Pinhole(40, 30, 40);

// Three segments side by side: left x < 15, middle 15 <= x < 25, right x >= 25. Left and middle
// lie on one flat surface at 1 m but their fitted planes disagree a little (1.00 and 1.02 m, the
// middle also tilted); the right one is a wall at 3 m (a depth edge).
LayeredDepthView ThreeSegments() {
  cv::Mat labels(kCamera.height, kCamera.width, CV_32S);
  for (int y = 0; y < kCamera.height; ++y) {
    for (int x = 0; x < kCamera.width; ++x) labels.at<int32_t>(y, x) = x < 15 ? 0 : x < 25 ? 1 : 2;
  }
  const cv::Vec3b grey(90, 90, 90);
  return testing::OneLayerView(
      kCamera, labels, {grey, grey, grey}, {{{0, 0, 1.0}, {0.0004, 0, 1.0 / 1.02 - 0.0004 * 20}, {0, 0, 1.0 / 3.0}}});
}

double StepAtSeam(const LayeredDepthView& view, double x) {
  return std::abs(view.segments[0].DepthAt(x, 15) - view.segments[1].DepthAt(x, 15));
}

TEST(SeamPlanesTest, PlanesOfOneSurfaceAgreeAtTheirSeamAndDepthEdgesStay) {
  const LayeredDepthView view = ThreeSegments();
  SeamPlaneReport report;
  SeamPlaneOptions options;
  options.seam_weight = 16;
  const LayeredDepthView joined = WithSeamPlanes(view, options, &report);
  const double before = StepAtSeam(view, 14.5), after = StepAtSeam(joined, 14.5);
  std::printf("step at the seam: %.2f mm before, %.2f mm after; %d seam pairs, %d planes changed\n",
              1e3 * before,
              1e3 * after,
              report.seam_pairs,
              report.planes_changed);
  EXPECT_EQ(report.seam_pairs, 30);  // one per row across x = 14 | 15; the wall's seam is a depth edge
  EXPECT_EQ(report.planes_changed, 2);
  EXPECT_GT(before, 0.015);
  EXPECT_LT(after, 0.2 * before);
  // The wall keeps its plane, and each joined plane stays near its own away from the seam.
  EXPECT_EQ(joined.segments[2].inv_depth_c, view.segments[2].inv_depth_c);
  EXPECT_NEAR(joined.segments[0].DepthAt(2, 15), 1.0, 0.02);
  EXPECT_NEAR(joined.segments[1].DepthAt(22, 15), view.segments[1].DepthAt(22, 15), 0.02);
  // depth_m follows the new planes; the caller's view is unchanged.
  EXPECT_NEAR(joined.depth_m.at<float>(15, 14), joined.segments[0].DepthAt(14, 15), 1e-5);
  EXPECT_EQ(view.depth_m.at<float>(15, 14), 1.0f);
  // Off (the default).
  WithSeamPlanes(view, SeamPlaneOptions(), &report);
  EXPECT_EQ(report.planes_changed, 0);
}

}  // namespace
}  // namespace px::render
