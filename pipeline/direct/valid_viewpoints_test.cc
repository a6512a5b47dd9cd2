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

// Aims at the centroid at `zoom` times f; with `watched`, the frame is composed on it (the
// search limits how much a valid frame enlarges it).
FramingRule AimAtCentroid(const SceneGeometry& scene, double zoom = 1.0, bool watched = false) {
  return [&scene, zoom, watched](const Eigen::Vector3d& centre) {
    Framing framing;
    framing.centre_in_world = centre;
    framing.cam_from_world = Rigid3::LookAt(centre, scene.centroid_in_world, scene.up_in_world);
    framing.focal_px = zoom * scene.focal_px;
    if (watched) framing.aim_in_world = scene.centroid_surface_in_world;
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

// A frame composed on the centroid 1.5 m ahead at 1.5f enlarges the capture's detail there 1.5
// times at z = 0; valid everywhere up to the 0.6 m limit, the search stops where that reaches
// twice (1.125 m from it, z 0.375 m). A clip half the capture's size has twice the detail to
// spare, and the 0.6 m limit holds; a zoom past the limit still holds at the capture's distance.
TEST(ValidViewpointsTest, TheFrontStopsWhereTheFrameEnlargesTheCaptureTwice) {
  SceneGeometry scene = Scene();
  const CoverageFunction everywhere = [](const CameraModel& camera, const Rigid3&) -> StatusOr<CoverageReport> {
    return ValidityCoverage(camera, true);
  };
  const ViewpointSearchOptions options;
  const auto front_z = [&](double zoom) -> double {
    CoverageProbe probe(&everywhere, 1.0, 2.0);
    StatusOr<ValidRegion> region =
        FindValidViewpoints(scene, AimAtCentroid(scene, zoom, true), &probe, options, Sweep::kAxis, true, false);
    EXPECT_TRUE(region.ok()) << region.status().ToString();
    if (!region.ok() || region->front.empty()) return -1;
    EXPECT_LE(AimEnlargement(scene, region->front[0].framing), std::max(2.0, zoom) / std::min(1.0, scene.output_scale));
    return region->front[0].framing.centre_in_world.z();
  };
  const double precision = SearchLimits(scene, options).precision_m;
  EXPECT_NEAR(front_z(1.5), 0.375, precision);
  EXPECT_LE(front_z(1.5), 0.375 + 1e-9);
  EXPECT_NEAR(front_z(3.0), 0.0, 1e-9);
  scene.output_scale = 0.5;
  EXPECT_NEAR(front_z(1.5), SearchLimits(scene, options).forward_m, precision);
  // A cell a little nearer an off-axis point than the capture's centre holds at z = 0 and
  // behind it, however much the zoom enlarges there.
  scene.output_scale = 1.0;
  scene.centroid_surface_in_world = Eigen::Vector3d(-0.1, -0.1, 0.5);  // over the first cell searched
  CoverageProbe grid_probe(&everywhere, 1.0, 2.0);
  StatusOr<ValidRegion> grid =
      FindValidViewpoints(scene, AimAtCentroid(scene, 3.0, true), &grid_probe, options, Sweep::kGrid, true, true);
  ASSERT_TRUE(grid.ok()) << grid.status().ToString();
  EXPECT_EQ(grid->valid_cells, 144);
  scene.centroid_surface_in_world = scene.centroid_in_world;
  // Without a point it is composed on, a frame is not limited.
  CoverageProbe probe(&everywhere, 1.0, 2.0);
  StatusOr<ValidRegion> unwatched =
      FindValidViewpoints(scene, AimAtCentroid(scene, 1.5), &probe, options, Sweep::kAxis, true, false);
  ASSERT_TRUE(unwatched.ok());
  EXPECT_NEAR(unwatched->front[0].framing.centre_in_world.z(), SearchLimits(scene, options).forward_m, precision);
}

}  // namespace
}  // namespace px::direct
