// Weak regions: propagated segments that continue one plain surface take the plane the whole
// surface's matching cost favours; a member whose own pixels reject it, a region of another
// colour and fitted segments keep their planes.
#include "pipeline/depth/weak_regions.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "pipeline/depth/plane_scene_test_util.h"

namespace px::depth {
namespace {

constexpr int kCols = 96, kRows = 64, kBlockPx = 8, kPerRow = kCols / kBlockPx;
constexpr double kFlatCost = 0.5;

InversePlane Level(double c) {
  InversePlane plane;
  plane.c = c;
  return plane;
}

const InversePlane kTrue = Level(0.50), kOffNear = Level(0.58), kOffFar = Level(0.43);

// Row 0 fitted on the true plane; rows 1 .. 7 propagated, their planes chained across the surface
// in bands: the true plane, one too near, one too far.
std::vector<SegmentPlane> ChainedPlanes(const Superpixels& segments) {
  std::vector<SegmentPlane> planes(segments.count);
  for (int s = 0; s < segments.count; ++s) {
    const int row = s / kPerRow, col = s % kPerRow;
    planes[s].source = row == 0 ? PlaneSource::kFitted : PlaneSource::kPropagated;
    planes[s].plane = row == 0 || col < 4 ? kTrue : col < 8 ? kOffNear : kOffFar;
  }
  return planes;
}

// Flat (no texture) everywhere but at the textured segments, which prefer the plane `at` their level.
PlaneCost CostWithTexture(const std::vector<int>& textured, const std::vector<double>& level) {
  return [textured, level](int s, const InversePlane& plane) {
    for (size_t i = 0; i < textured.size(); ++i) {
      if (textured[i] == s) return kFlatCost + 2.0 * std::abs(plane.c - level[i]);
    }
    return kFlatCost;
  };
}

int Segment(int row, int col) { return row * kPerRow + col; }

TEST(WeakRegionsTest, APlainSurfaceTakesThePlaneItsTexturedSegmentsFavour) {
  const Superpixels segments = testing::BlockSegments(kCols, kRows, kBlockPx);
  std::vector<SegmentPlane> planes = ChainedPlanes(segments);
  // Two textured segments among the wrongly chained ones, both favouring the true plane.
  const PlaneCost cost = CostWithTexture({Segment(5, 6), Segment(6, 10)}, {kTrue.c, kTrue.c});
  const WeakRegionStats stats = UnifyWeakRegions(segments, cost, WeakRegionOptions{}, &planes);
  EXPECT_EQ(stats.regions, 1);
  EXPECT_EQ(stats.changed_segments, 7 * 8);  // every propagated segment off the true plane
  for (int s = 0; s < segments.count; ++s) EXPECT_EQ(planes[s].plane.c, kTrue.c) << "segment " << s;
}

TEST(WeakRegionsTest, AMemberWhoseOwnPixelsRejectThePlaneKeepsItsOwn) {
  const Superpixels segments = testing::BlockSegments(kCols, kRows, kBlockPx);
  std::vector<SegmentPlane> planes = ChainedPlanes(segments);
  const int dissenter = Segment(3, 9);  // holds the far plane and its texture says so
  const PlaneCost cost = CostWithTexture({Segment(5, 6), Segment(6, 10), dissenter}, {kTrue.c, kTrue.c, kOffFar.c});
  UnifyWeakRegions(segments, cost, WeakRegionOptions{}, &planes);
  EXPECT_EQ(planes[dissenter].plane.c, kOffFar.c);
  EXPECT_EQ(planes[Segment(3, 10)].plane.c, kTrue.c);
}

TEST(WeakRegionsTest, ARegionOfAnotherColourAndFittedSegmentsKeepTheirPlanes) {
  Superpixels segments = testing::BlockSegments(kCols, kRows, kBlockPx);
  std::vector<SegmentPlane> planes = ChainedPlanes(segments);
  // Columns 8 .. 11 are another surface: another colour, its texture favouring the far plane.
  // Its top rows copied the true plane from the fitted row above; one segment of texture says
  // far, against two of the first surface's that say true (one region, they would outvote it).
  for (int s = 0; s < segments.count; ++s) {
    if (s % kPerRow < 8) continue;
    segments.mean_lab[s] = cv::Vec3f(60, 150, 110);
    if (s / kPerRow <= 3) planes[s].plane = kTrue;
  }
  planes[Segment(4, 2)].source = PlaneSource::kFitted;
  planes[Segment(4, 2)].plane = kOffNear;
  const PlaneCost cost = CostWithTexture({Segment(5, 6), Segment(6, 3), Segment(6, 9)}, {kTrue.c, kTrue.c, kOffFar.c});
  const WeakRegionStats stats = UnifyWeakRegions(segments, cost, WeakRegionOptions{}, &planes);
  EXPECT_EQ(stats.regions, 2);
  EXPECT_EQ(planes[Segment(4, 2)].plane.c, kOffNear.c);  // fitted: never changed
  for (int row = 1; row < 8; ++row) {
    EXPECT_EQ(planes[Segment(row, 5)].plane.c, kTrue.c) << "row " << row;
    EXPECT_EQ(planes[Segment(row, 10)].plane.c, kOffFar.c) << "row " << row;
  }
}

}  // namespace
}  // namespace px::depth
