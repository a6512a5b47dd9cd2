#include "pipeline/render/view_mesh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <string>

#include "pipeline/core/camera_model.h"
#include "pipeline/core/rigid3.h"

namespace px::render {
namespace {

// A 3x3 lattice 25 mm apart in the z = 0 plane, every camera looking down +z.
ViewMesh Lattice3x3() {
  std::vector<Eigen::Vector3d> centres;
  std::vector<Eigen::Matrix3d> rotations;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      centres.emplace_back((c - 1) * 0.025, (r - 1) * 0.025, 0.0);
      rotations.push_back(Eigen::Matrix3d::Identity());
    }
  }
  return ViewMesh::Build(centres, rotations).value();
}

double Sum(const ViewSlots& s) { return s.weight[0] + s.weight[1] + s.weight[2]; }

std::set<int> ViewsIn(const ViewSlots& s) {
  std::set<int> views;
  for (int k = 0; k < 3; ++k) {
    if (s.view[k] != ViewSlots::kNone) views.insert(s.view[k]);
  }
  return views;
}

double WeightOf(const ViewSlots& s, int view) {
  for (int k = 0; k < 3; ++k) {
    if (s.view[k] == view) return s.weight[k];
  }
  return 0;
}

TEST(ViewMeshTest, BuildsTheDelaunayMeshAndItsExtensionRing) {
  const ViewMesh mesh = Lattice3x3();
  EXPECT_EQ(mesh.kind(), ViewMesh::Kind::kTriangles);
  EXPECT_EQ(mesh.NumViews(), 9);
  // 3x3 points: 8 Delaunay triangles; the hull has 8 vertices and 8 edges, each adding two.
  EXPECT_EQ(mesh.NumDelaunayTriangles(), 8);
  EXPECT_EQ(mesh.triangles().size(), 8u + 16u);
  ASSERT_EQ(mesh.vertices().size(), 9u + 8u);
  // Duplicates sit radially outward at four times the distance from the centroid.
  for (size_t i = 9; i < mesh.vertices().size(); ++i) {
    const ViewMesh::Vertex& dup = mesh.vertices()[i];
    const Eigen::Vector2d original = mesh.vertices()[dup.view].position;
    EXPECT_NEAR((dup.position - 4.0 * original).norm(), 0.0, 1e-12) << "duplicate " << i;
  }
  EXPECT_NEAR(std::abs(mesh.normal().z()), 1.0, 1e-12);
  EXPECT_GT(mesh.normal().z(), 0);  // towards the scene
}

TEST(ViewMeshTest, WeightsAreBarycentricAndSumToOneEverywhere) {
  const ViewMesh mesh = Lattice3x3();
  // At a lens: that lens alone.
  for (int view = 0; view < 9; ++view) {
    const ViewSlots at = mesh.WeightsAt(mesh.vertices()[view].position);
    EXPECT_NEAR(WeightOf(at, view), 1.0, 1e-6) << "view " << view;
  }
  // Halfway between the centre (4) and its right neighbour (5).
  const ViewSlots half = mesh.WeightsAt(Eigen::Vector2d(0.0125, 0.0));
  EXPECT_NEAR(WeightOf(half, 4), 0.5, 1e-6);
  EXPECT_NEAR(WeightOf(half, 5), 0.5, 1e-6);
  // A grid of points inside, on the extension ring and far outside: weights in [0, 1], sum 1,
  // each view at most once.
  for (double u = -0.3; u <= 0.3; u += 0.0071) {
    for (double v = -0.3; v <= 0.3; v += 0.0093) {
      const ViewSlots s = mesh.WeightsAt(Eigen::Vector2d(u, v));
      ASSERT_NEAR(Sum(s), 1.0, 1e-5) << u << "," << v;
      std::set<int> seen;
      for (int k = 0; k < 3; ++k) {
        ASSERT_GE(s.weight[k], -1e-6);
        if (s.view[k] == ViewSlots::kNone) continue;
        ASSERT_LT(s.view[k], 9);
        ASSERT_TRUE(seen.insert(s.view[k]).second) << "view twice at " << u << "," << v;
      }
    }
  }
  // Far outside the extended mesh the nearest boundary point decides: to the right only the
  // right column's lenses contribute.
  const ViewSlots far_right = mesh.WeightsAt(Eigen::Vector2d(1.0, 0.0));
  EXPECT_NEAR(WeightOf(far_right, 2) + WeightOf(far_right, 5) + WeightOf(far_right, 8), 1.0, 1e-6);
}

// Compares ComputeWeights with WeightsAt pixel by pixel for cameras at `centres`, each turned by
// every angle of `turns_deg`: the same weights, and with `same_views` the same views in the slots
// (in any order: ALGORITHM.md section 3), zero weights too. Returns the pixels compared.
int CompareTilesWithPixels(const ViewMesh& mesh,
                           const std::vector<Eigen::Vector3d>& centres,
                           const std::vector<double>& turns_deg,
                           bool same_views) {
  const CameraModel camera = CameraModel::Pinhole(96, 64, 80);
  int compared = 0;
  for (const Eigen::Vector3d& centre : centres) {
    for (double turn : turns_deg) {
      const Eigen::Quaterniond rotation(Eigen::AngleAxisd(turn * M_PI / 180, Eigen::Vector3d(0.3, 1, 0).normalized()));
      const Rigid3 pose(rotation, -(rotation * centre));
      std::vector<ViewSlots> tiles;
      mesh.ComputeWeights(camera, pose, &tiles, 1.0);
      for (int y = 0; y < camera.height; ++y) {
        for (int x = 0; x < camera.width; ++x) {
          const ViewSlots pixel = mesh.WeightsAt(mesh.PlanePointOfPixel(camera, pose, x, y));
          const ViewSlots& tile = tiles[static_cast<size_t>(y) * camera.width + x];
          const std::string where = "pixel " + std::to_string(x) + "," + std::to_string(y) + ", centre " +
                                    ::testing::PrintToString(centre.transpose().eval()) + ", turned " +
                                    std::to_string(turn);
          if (same_views) {
            EXPECT_EQ(ViewsIn(tile), ViewsIn(pixel)) << where;
          }
          for (int view = 0; view < mesh.NumViews(); ++view) {
            EXPECT_NEAR(WeightOf(tile, view), WeightOf(pixel, view), 2e-5) << "view " << view << " at " << where;
          }
          if (::testing::Test::HasFailure()) return compared;
          ++compared;
        }
      }
    }
  }
  return compared;
}

// ComputeWeights' tiles (inside one triangle, or outside the mesh in one region of the nearest
// outer edge or vertex) give what WeightsAt gives pixel by pixel, for cameras whose pixels see the
// plane inside the mesh, on its ring, far outside it (in front of the lattice: a dolly in), and
// past the horizon (turned).
TEST(ViewMeshTest, ComputeWeightsMatchesThePixelByPixelWeights) {
  EXPECT_EQ(CompareTilesWithPixels(Lattice3x3(),
                                   {{0.004, -0.003, -0.05}, {0.01, 0.0, 0.3}, {-0.02, 0.015, 0.7}, {0.0, 0.0, 0.02}},
                                   {0, 3, 10, 70},
                                   false),
            16 * 96 * 64);
}

// A hand-held sweep's four centres (a real set's): nearly on a line, so Delaunay leaves a sliver
// out and the extended mesh's outline is not convex. Cameras whose whole frame meets the plane
// outside the mesh (beside it, close to its plane, far above it) fill tiles from the outer regions
// only where each holds the whole tile: the same weights and the same views as pixel by pixel.
TEST(ViewMeshTest, ComputeWeightsMatchesThePixelByPixelWeightsOutsideANonConvexOutline) {
  const std::vector<Eigen::Vector3d> centres = {
      {-0.054, 0.010, 0}, {-0.015, -0.001, 0}, {0.018, -0.006, 0}, {0.051, -0.003, 0}};
  const ViewMesh mesh = ViewMesh::Build(centres, std::vector<Eigen::Matrix3d>(4, Eigen::Matrix3d::Identity())).value();
  EXPECT_EQ(CompareTilesWithPixels(mesh,
                                   {{0.04, 0.09, -0.004},
                                    {-0.04, 0.12, -0.012},
                                    {0.0, -0.08, 0.3},
                                    {0.2, 0.05, -0.02},
                                    {0.0, 0.03, -0.002},
                                    {0.1, -0.03, -0.001},
                                    {-0.08, 0.0, -0.003},
                                    {0.03, 0.01, 0.05},
                                    {0.01, 0.005, 1.0},
                                    {0.3, 0.2, 2.0}},
                                   {0, 3, 10, 40},
                                   true),
            40 * 96 * 64);
}

TEST(ViewMeshTest, CameraInFrontOfTheMeshAndOnItUsesTheNearestPointOfTheMesh) {
  const ViewMesh mesh = Lattice3x3();
  const CameraModel camera = CameraModel::Pinhole(64, 48, 56);
  // A camera on the mesh plane right at the centre lens: every pixel's line meets the plane at
  // its centre, so every pixel takes the centre view alone (the near-mesh rule, no singularity).
  std::vector<ViewSlots> slots;
  const Eigen::Vector3d at_lens(0.0, 0.0, 0.0);
  mesh.ComputeWeights(camera, Rigid3(Eigen::Quaterniond::Identity(), -at_lens), &slots);
  ASSERT_EQ(slots.size(), 64u * 48u);
  for (const ViewSlots& s : slots) ASSERT_NEAR(WeightOf(s, 4), 1.0, 1e-5);
  // 1 mm in front of the mesh (towards the scene) at (5 mm, 0): lines meet the plane behind the
  // camera ("backwards projection"); the image centre still gets the views around (5 mm, 0) and
  // every pixel's weights sum to one.
  const Eigen::Vector3d in_front(0.005, 0.0, 0.001);
  mesh.ComputeWeights(camera, Rigid3(Eigen::Quaterniond::Identity(), -in_front), &slots);
  for (const ViewSlots& s : slots) ASSERT_NEAR(Sum(s), 1.0, 1e-5);
  const ViewSlots& centre_pixel = slots[24 * 64 + 32];
  EXPECT_GT(WeightOf(centre_pixel, 4) + WeightOf(centre_pixel, 5), 0.95);
  EXPECT_GT(WeightOf(centre_pixel, 4), WeightOf(centre_pixel, 5));  // 5 mm of 25 from lens 4
  // Pixels to the right look right and, projected backwards, meet the plane to the left.
  const ViewSlots& right_pixel = slots[24 * 64 + 63];
  const ViewSlots& left_pixel = slots[24 * 64 + 0];
  EXPECT_GT(WeightOf(right_pixel, 3) + WeightOf(right_pixel, 4), WeightOf(left_pixel, 3) + WeightOf(left_pixel, 4));
}

TEST(ViewMeshTest, DegenerateSetsStillGiveWeightsThatSumToOne) {
  // One view: weight 1 everywhere.
  const ViewMesh one = ViewMesh::Build({Eigen::Vector3d::Zero()}, {Eigen::Matrix3d::Identity()}).value();
  EXPECT_EQ(one.kind(), ViewMesh::Kind::kPoint);
  EXPECT_NEAR(WeightOf(one.WeightsAt(Eigen::Vector2d(3, 4)), 0), 1.0, 1e-9);
  // A row of three: linear along the line.
  const ViewMesh line =
      ViewMesh::Build({Eigen::Vector3d(-0.1, 0, 0), Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.1, 0, 0)},
                      std::vector<Eigen::Matrix3d>(3, Eigen::Matrix3d::Identity()))
          .value();
  EXPECT_EQ(line.kind(), ViewMesh::Kind::kLine);
  const ViewSlots s = line.WeightsAt(Eigen::Vector2d(0.025, 0.3));
  EXPECT_NEAR(Sum(s), 1.0, 1e-9);
  EXPECT_NEAR(WeightOf(s, 1), 0.75, 1e-9);
  EXPECT_NEAR(WeightOf(s, 2), 0.25, 1e-9);
  // No views is an error, not a crash.
  EXPECT_FALSE(ViewMesh::Build({}, {}).ok());
}

// Where fewer than three views are blended, the free slot holds the nearest other view at weight
// 0 (a witness that settles their disagreements): along a line, in the extension ring, outside.
TEST(ViewMeshTest, TwoBlendedViewsGetTheNearestOtherViewAsAWitness) {
  const auto witness_of = [](const ViewSlots& s) {
    int witness = -1, blended = 0;
    for (int k = 0; k < 3; ++k) {
      if (s.view[k] == ViewSlots::kNone) continue;
      if (s.weight[k] > 0) {
        ++blended;
      } else {
        witness = s.view[k];
      }
    }
    return blended == 2 ? witness : -2;
  };
  std::vector<Eigen::Vector3d> row;
  for (int i = 0; i < 4; ++i) row.emplace_back(0.1 * i, 0, 0);
  const ViewMesh line = ViewMesh::Build(row, std::vector<Eigen::Matrix3d>(4, Eigen::Matrix3d::Identity())).value();
  ASSERT_EQ(line.kind(), ViewMesh::Kind::kLine);
  const auto on_line = [&](double x) { return line.WeightsAt(line.ToPlane(Eigen::Vector3d(x, 0, 0))); };
  EXPECT_EQ(witness_of(on_line(0.05)), 2);  // between 0 and 1: 2 is the only other neighbour
  EXPECT_EQ(witness_of(on_line(0.25)), 1);  // between 2 and 3: 1 is the nearer
  std::vector<ViewSlots> slots;
  const CameraModel camera = CameraModel::Pinhole(64, 48, 60);
  line.ComputeWeights(camera, Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-0.15, 0, 0.5)), &slots, 0.5);
  for (const ViewSlots& s : slots) EXPECT_NEAR(Sum(s), 1.0, 1e-5);

  const ViewMesh lattice = Lattice3x3();
  // Out beyond the hull edge between views 2 and 5: the third corner of
  // the lattice's triangle on that edge witnesses.
  const Eigen::Vector2d& p2 = lattice.vertices()[2].position;
  const Eigen::Vector2d& p5 = lattice.vertices()[5].position;
  int third = -1;
  for (int t = 0; t < lattice.NumDelaunayTriangles(); ++t) {
    std::set<int> corners;
    for (const int v : lattice.triangles()[t]) corners.insert(lattice.vertices()[v].view);
    if (corners.count(2) && corners.count(5))
      third = *std::find_if(corners.begin(), corners.end(), [](int v) { return v != 2 && v != 5; });
  }
  ASSERT_GE(third, 0);
  const Eigen::Vector2d outward = 0.5 * (p2 + p5) - lattice.vertices()[4].position;
  for (const double reach : {0.5, 2.0, 3.5}) {  // in the ring, and outside the extended mesh
    const ViewSlots beyond = lattice.WeightsAt(0.5 * (p2 + p5) + reach * outward);
    EXPECT_GT(WeightOf(beyond, 2) + WeightOf(beyond, 5), 0.99) << reach;
    EXPECT_EQ(witness_of(beyond), third) << reach;
  }
}

// Four hand-held centres nearly on a line (kpankov_office_4views' sideways sweep, as its plane
// holds them): the thin triangles along the hull have circumcircles reaching Subdiv2D's outer
// vertices at its first distance, which left no triangle at all. The mesh covers their hull.
TEST(ViewMeshTest, CentresNearlyOnALineStillCoverTheirHull) {
  const std::vector<Eigen::Vector2d> sweep = {{0, 20.938}, {337.512, 0}, {694.421, 16.739}, {1000, 51.702}};
  std::vector<Eigen::Vector3d> centres;
  for (const Eigen::Vector2d& p : sweep) centres.emplace_back(p.x() * 1e-4, p.y() * 1e-4, 0.0);
  StatusOr<ViewMesh> mesh = ViewMesh::Build(centres, std::vector<Eigen::Matrix3d>(4, Eigen::Matrix3d::Identity()));
  ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
  EXPECT_EQ(mesh->kind(), ViewMesh::Kind::kTriangles);
  // Four points in convex position (1 and 2 below the chord 0-3): two triangles, whose areas add
  // up to the quadrilateral's.
  ASSERT_EQ(mesh->NumDelaunayTriangles(), 2);
  double area = 0;
  for (int t = 0; t < mesh->NumDelaunayTriangles(); ++t) {
    const auto& tri = mesh->triangles()[t];
    const Eigen::Vector2d a = mesh->vertices()[tri[0]].position, b = mesh->vertices()[tri[1]].position,
                          c = mesh->vertices()[tri[2]].position;
    area += 0.5 * std::abs((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x());
  }
  double hull = 0;  // shoelace over 0, 1, 2, 3
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector3d& p = centres[k];
    const Eigen::Vector3d& q = centres[(k + 1) % 4];
    hull += 0.5 * (p.x() * q.y() - q.x() * p.y());
  }
  EXPECT_NEAR(area, std::abs(hull), 1e-6 * std::abs(hull));
  // Every point of the hull gets weights summing to one from its triangle.
  EXPECT_NEAR(Sum(mesh->WeightsAt(mesh->vertices()[1].position + Eigen::Vector2d(0, 1e-4))), 1.0, 1e-9);
}

// ComputeWeights flattens each band of rows as it makes it: the same weights as flattening the
// whole frame afterwards, bit for bit, for the square root (one 4-lane step a slot) and for pow.
TEST(ViewMeshTest, ComputeWeightsFlattensAsItGoes) {
  const ViewMesh mesh = Lattice3x3();
  const CameraModel camera = CameraModel::Pinhole(83, 61, 70.0);  // bands of 16 rows, the last one short
  const Rigid3 pose(Eigen::Quaterniond(Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitY())),
                    -Eigen::Vector3d(0.006, -0.004, -0.02));
  for (const double exponent : {0.5, 0.7}) {
    std::vector<ViewSlots> fused, afterwards;
    mesh.ComputeWeights(camera, pose, &fused, exponent);
    mesh.ComputeWeights(camera, pose, &afterwards);
    FlattenViewingWeights(exponent, &afterwards);
    ASSERT_EQ(fused.size(), afterwards.size());
    int differing = 0, several_views = 0;
    for (size_t i = 0; i < fused.size(); ++i) {
      differing += fused[i].view != afterwards[i].view || fused[i].weight != afterwards[i].weight;
      several_views += fused[i].view[1] != ViewSlots::kNone;
    }
    EXPECT_EQ(differing, 0) << "exponent " << exponent;
    EXPECT_GT(several_views, static_cast<int>(fused.size()) / 2) << "the frame blends views";
  }
}

}  // namespace
}  // namespace px::render

namespace px::render {
namespace {

// The flattened weights (exponent 0.5) along a straight walk of the mesh point across the lattice:
// they sum to 1, keep the barycentric order of the views, leave a lens alone at weight 1 and a
// view outside the pixel's triangle at 0, and change by no more per step than they can on a
// continuous function (no jump where the walk crosses a triangle edge: no popping on a camera path).
TEST(ViewMeshTest, FlattenedWeightsSumToOneAndStayContinuous) {
  const ViewMesh mesh = Lattice3x3();
  constexpr int kSteps = 2000;
  std::vector<ViewSlots> walk(kSteps + 1);
  for (int i = 0; i <= kSteps; ++i) {
    const double t = static_cast<double>(i) / kSteps;
    walk[i] = mesh.WeightsAt(Eigen::Vector2d(-0.03 + 0.06 * t, -0.02 + 0.037 * t));
  }
  std::vector<ViewSlots> flat = walk;
  FlattenViewingWeights(0.5, &flat);
  double largest_step = 0, largest_linear_step = 0;
  for (int i = 0; i <= kSteps; ++i) {
    EXPECT_NEAR(Sum(flat[i]), 1.0, 1e-5) << "step " << i;
    for (int view = 0; view < 9; ++view) {
      const double before = WeightOf(walk[i], view), after = WeightOf(flat[i], view);
      if (before == 0) {
        EXPECT_EQ(after, 0) << "step " << i << " view " << view;
      }
      if (i > 0) largest_step = std::max(largest_step, std::abs(after - WeightOf(flat[i - 1], view)));
      if (i > 0) largest_linear_step = std::max(largest_linear_step, std::abs(before - WeightOf(walk[i - 1], view)));
    }
  }
  // sqrt is steep near 0 but continuous (Hoelder-1/2): a step of the barycentric weights of d
  // moves a flattened weight by at most about sqrt(d) (here d ~ 1.4e-3, sqrt 0.037); a jump where
  // the walk crosses a triangle edge would be tenths.
  EXPECT_LT(largest_step, 1.5 * std::sqrt(largest_linear_step));
  EXPECT_LT(largest_step, 0.1);
  // At a lens the flattened weight is still 1; halfway between two lenses still 0.5 / 0.5.
  std::vector<ViewSlots> points = {mesh.WeightsAt(mesh.vertices()[4].position),
                                   mesh.WeightsAt(Eigen::Vector2d(0.0125, 0.0)),
                                   mesh.WeightsAt(Eigen::Vector2d(0.02, 0.004))};
  const std::vector<ViewSlots> linear = points;
  FlattenViewingWeights(0.5, &points);
  EXPECT_NEAR(WeightOf(points[0], 4), 1.0, 1e-6);
  EXPECT_NEAR(WeightOf(points[1], 4), 0.5, 1e-6);
  EXPECT_NEAR(WeightOf(points[1], 5), 0.5, 1e-6);
  // Inside a triangle the lighter views gain: closer to an even share than the barycentric weights.
  double spread_linear = 0, spread_flat = 0;
  for (int k = 0; k < 3; ++k) {
    spread_linear = std::max(spread_linear, std::abs(linear[2].weight[k] - 1.0 / 3));
    spread_flat = std::max(spread_flat, std::abs(points[2].weight[k] - 1.0 / 3));
  }
  EXPECT_LT(spread_flat, spread_linear);
  // Exponent 1 changes nothing.
  std::vector<ViewSlots> same = linear;
  FlattenViewingWeights(1.0, &same);
  for (size_t i = 0; i < same.size(); ++i) {
    for (int k = 0; k < 3; ++k) EXPECT_EQ(same[i].weight[k], linear[i].weight[k]);
  }
}

}  // namespace
}  // namespace px::render
