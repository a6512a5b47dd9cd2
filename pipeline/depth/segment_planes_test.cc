// Unfitted segments take a neighbour's plane: by matching cost, and where the cost cannot tell
// (no texture; an edge along the baselines), the neighbour that looks like them.
#include "pipeline/depth/segment_planes.h"

#include <gtest/gtest.h>

#include "pipeline/depth/plane_scene_test_util.h"

namespace px::depth {
namespace {

constexpr double kNear = 1.0;       // inverse depth of the desk top, 1/m
constexpr double kFar = 1.0 / 3.0;  // of the recess below it
const cv::Vec3f kLightWood(190, 135, 160);
const cv::Vec3f kDarkRecess(60, 132, 140);

// Three bands of blocks, top to bottom: a fitted near surface, an unfitted strip, a fitted far
// surface, the strip coloured `strip`. Segments 0..3 are the top band, 4..7 the strip, 8..11 the
// bottom band.
struct Strip {
  Superpixels segments = testing::BlockSegments(32, 24, 8);
  std::vector<SegmentPlane> planes;

  explicit Strip(const cv::Vec3f& strip) {
    planes.resize(segments.count);
    for (int s = 0; s < segments.count; ++s) {
      const int band = s / 4;
      segments.mean_lab[s] = band == 0 ? kLightWood : band == 1 ? strip : kDarkRecess;
      if (band == 1) continue;
      planes[s].plane = {0, 0, band == 0 ? kNear : kFar};
      planes[s].source = PlaneSource::kFitted;
      planes[s].support = 0.9f;
      planes[s].confidence = 0.8f;
    }
  }
  double StripInverseDepth(int s) const { return planes[s].plane.c; }
};

// A cost flat in depth (the strip matches every plane alike) plus `near_bias` for the near plane.
PlaneCost FlatCost(double near_bias = 0) {
  return [near_bias](int, const InversePlane& plane) { return 0.5 + (plane.c > 0.5 ? near_bias : 0.0); };
}

TEST(AssignUnfittedSegmentsTest, AStripTheCostCannotPlaceContinuesTheSurfaceItLooksLike) {
  Strip light(kLightWood + cv::Vec3f(6, 0, 0));  // a lit edge of the desk top
  AssignUnfittedSegments(light.segments, FlatCost(), {}, {}, 0.02, &light.planes);
  for (int s = 4; s < 8; ++s) {
    EXPECT_EQ(light.planes[s].source, PlaneSource::kPropagated);
    EXPECT_DOUBLE_EQ(light.StripInverseDepth(s), kNear) << "segment " << s;
  }
  Strip dark(kDarkRecess + cv::Vec3f(5, 0, 0));  // a shadow that belongs to the recess
  AssignUnfittedSegments(dark.segments, FlatCost(), {}, {}, 0.02, &dark.planes);
  for (int s = 4; s < 8; ++s) EXPECT_DOUBLE_EQ(dark.StripInverseDepth(s), kFar) << "segment " << s;
}

TEST(AssignUnfittedSegmentsTest, WhereColourCannotTellEitherTheBackgroundContinues) {
  Strip between((kLightWood + kDarkRecess) / 2);
  AssignUnfittedSegments(between.segments, FlatCost(), {}, {}, 0.02, &between.planes);
  for (int s = 4; s < 8; ++s) EXPECT_DOUBLE_EQ(between.StripInverseDepth(s), kFar) << "segment " << s;
}

TEST(AssignUnfittedSegmentsTest, ACostBeyondTheMarginDecidesWhateverTheColour) {
  Strip light(kLightWood);
  AssignUnfittedSegments(light.segments, FlatCost(0.1), {}, {}, 0.02, &light.planes);  // near costs more
  for (int s = 4; s < 8; ++s) EXPECT_DOUBLE_EQ(light.StripInverseDepth(s), kFar) << "segment " << s;
}

}  // namespace
}  // namespace px::depth
