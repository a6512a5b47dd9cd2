#include "pipeline/direct/valid_viewpoints.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <mutex>
#include <set>
#include <thread>

#include "pipeline/direct/test_scene.h"

namespace px::direct {
namespace {

SceneGeometry Scene() { return TestCaptureScene(); }

// The valid region's surfaces over the grid (x, y in [-0.1, 0.1] m): tilted planes, the front
// one with a 12 cm step across x = 0.03 m (a neighbour's answer far off) and past the 0.6 m
// limit in the grid's far corner.
double FrontZ(double x, double y) { return 0.30 + 1.5 * x + 0.8 * y + (x > 0.03 ? 0.12 : 0.0); }
double BackZ(double x, double y) { return -0.50 + 2.0 * y - 1.0 * x; }

// H(V) 0 between the surfaces, 10 outside, at the camera's own size (so the probe reads it as is).
CoverageFunction SlabCoverage(std::set<std::thread::id>* threads, std::mutex* mutex) {
  return [threads, mutex](const CameraModel& camera, const Rigid3& cam_from_world) -> StatusOr<CoverageReport> {
    {
      const std::lock_guard<std::mutex> lock(*mutex);
      threads->insert(std::this_thread::get_id());
    }
    const Eigen::Vector3d c = CameraCentre(cam_from_world);
    const bool inside = c.z() <= FrontZ(c.x(), c.y()) && c.z() >= BackZ(c.x(), c.y());
    return ValidityCoverage(camera, inside);
  };
}

FramingRule AimAtCentroid(const SceneGeometry& scene) {
  return [&scene](const Eigen::Vector3d& centre) {
    Framing framing;
    framing.centre_in_world = centre;
    framing.cam_from_world = Rigid3::LookAt(centre, scene.centroid_in_world, scene.up_in_world);
    framing.focal_px = scene.focal_px;
    return framing;
  };
}

// Every cell's answers are valid and within the search precision of the region's surface, the
// grid searched as one chain or as two side by side; each direction takes a few probes a cell.
TEST(ValidViewpointsTest, FindsEachCellsFrontAndBackWithinThePrecision) {
  const SceneGeometry scene = Scene();
  const ViewpointSearchOptions options;
  const ZLimits z = SearchLimits(scene, options);
  for (const bool concurrent : {false, true}) {
    std::set<std::thread::id> threads;
    std::mutex mutex;
    const CoverageFunction coverage = SlabCoverage(&threads, &mutex);
    CoverageProbe probe(&coverage, 1.0, 2.0, concurrent);
    StatusOr<ValidRegion> region =
        FindValidViewpoints(scene, AimAtCentroid(scene), &probe, options, Sweep::kGrid, true, true);
    ASSERT_TRUE(region.ok()) << region.status().ToString();
    EXPECT_EQ(region->cells, 144);
    EXPECT_EQ(region->valid_cells, 144);
    ASSERT_EQ(region->front.size(), 144u);
    ASSERT_EQ(region->back.size(), 144u);
    for (const Candidate& front : region->front) {
      const Eigen::Vector3d c = front.framing.centre_in_world;
      const double surface = std::min(FrontZ(c.x(), c.y()), z.forward_m);  // the search stops at the limit
      EXPECT_LE(c.z(), surface + 1e-12) << "cell " << front.cell;
      EXPECT_LT(surface - c.z(), z.precision_m + 1e-9) << "cell " << front.cell;
    }
    for (const Candidate& back : region->back) {
      const Eigen::Vector3d c = back.framing.centre_in_world;
      const double surface = BackZ(c.x(), c.y());
      EXPECT_GE(c.z(), surface - 1e-12) << "cell " << back.cell;
      EXPECT_LT(c.z() - surface, z.precision_m + 1e-9) << "cell " << back.cell;
    }
    // From scratch a direction takes about 8 probes (doubling from 75 mm, halving to 15 mm).
    const double per_direction = region->probes / (2.0 * region->cells);
    EXPECT_LT(per_direction, 4.0);
    EXPECT_EQ(region->probes, probe.calls());
    std::printf("[figures] %s: %d probes, %.2f a cell and direction, on %zu thread(s)\n",
                concurrent ? "two chains side by side" : "one chain",
                region->probes,
                per_direction,
                threads.size());  // two chains may share one thread when the workers are busy
  }
}

// An axis sweep (dolly-out, dolly zoom) searches the centre cell only, to the same precision.
TEST(ValidViewpointsTest, AnAxisSweepSearchesTheCentreCellOnly) {
  const SceneGeometry scene = Scene();
  std::set<std::thread::id> threads;
  std::mutex mutex;
  const CoverageFunction coverage = SlabCoverage(&threads, &mutex);
  CoverageProbe probe(&coverage, 1.0, 2.0);
  StatusOr<ValidRegion> region =
      FindValidViewpoints(scene, AimAtCentroid(scene), &probe, ViewpointSearchOptions(), Sweep::kAxis, true, true);
  ASSERT_TRUE(region.ok()) << region.status().ToString();
  EXPECT_EQ(region->cells, 1);
  ASSERT_EQ(region->front.size(), 1u);
  ASSERT_EQ(region->back.size(), 1u);
  EXPECT_NEAR(region->front[0].framing.centre_in_world.z(), FrontZ(0, 0), 0.015);
  EXPECT_NEAR(region->back[0].framing.centre_in_world.z(), BackZ(0, 0), 0.015);
}

}  // namespace
}  // namespace px::direct
