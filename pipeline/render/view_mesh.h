// The view mesh of paper section 6 (ALGORITHM.md sections 2 and 3): a triangle mesh over the input
// views' centres of projection, extended past its boundary, that says for every ray of a novel
// camera which three views contribute and with which weights (barycentric coordinates where the
// ray's line meets the mesh plane).
//
// The GL back end builds a twin of it (gl/gl_view_mesh.h) by the same rules; both must triangulate
// alike (OpenCV's Delaunay breaks ties on a regular lattice in its own way), which
// render/gl/gl_agreement_test checks through the weights.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "pipeline/core/camera_model.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/status.h"

namespace px::render {

// The (up to) three views blended at one pixel. A view appears at most once; unused slots hold
// kNone with weight 0. Weights are >= 0 and sum to 1. Where fewer than three views are blended
// (between two views of a line, in the extension ring, outside the mesh by an outer edge) a free
// slot holds a witness at weight 0: the other view nearest that stretch of the mesh. It is drawn
// but never blended, not even where the others saw nothing (the hole stages decide there); its
// colour settles a disagreement between the two (the one it contradicts yields,
// preview_compositor.cc).
struct ViewSlots {
  static constexpr uint8_t kNone = 255;
  std::array<uint8_t, 3> view = {kNone, kNone, kNone};  // index into the views the mesh was built on
  uint8_t witness = kNone;                              // the slot holding a witness, or kNone
  std::array<float, 3> weight = {0, 0, 0};

  // The slots that may be blended, as bits (1 << slot): all but the witness's.
  int BlendableBits() const { return witness == kNone ? 7 : 7 & ~(1 << witness); }
};

class ViewMesh {
 public:
  // How many views a mesh may have (slots store a view in 8 bits).
  static constexpr int kMaxViews = 254;
  enum class Kind { kPoint, kLine, kTriangles };

  struct Vertex {
    Eigen::Vector2d position;  // in the mesh plane (metres along axis_u, axis_v from the origin)
    int view = 0;              // the input view it carries (a boundary duplicate carries its original's)
  };

  // centres_in_world[i] and world_from_cam_rotations[i] describe view i (its COP and R^T, whose
  // columns are the camera's x, y, z axes in the world). At least one view, at most kMaxViews.
  static StatusOr<ViewMesh> Build(const std::vector<Eigen::Vector3d>& centres_in_world,
                                  const std::vector<Eigen::Matrix3d>& world_from_cam_rotations);

  Kind kind() const { return kind_; }
  int NumViews() const { return num_views_; }
  // The mesh plane: origin (mean COP), unit normal towards the scene, in-plane axes.
  const Eigen::Vector3d& origin() const { return origin_; }
  const Eigen::Vector3d& normal() const { return normal_; }
  const Eigen::Vector3d& axis_u() const { return axis_u_; }
  const Eigen::Vector3d& axis_v() const { return axis_v_; }
  Eigen::Vector2d ToPlane(const Eigen::Vector3d& point_in_world) const;

  // One vertex per view (index = view) that is part of the mesh, then the boundary duplicates.
  const std::vector<Vertex>& vertices() const { return vertices_; }
  // Counter-clockwise triangles into vertices(): the Delaunay ones, then the extension ring.
  const std::vector<std::array<int, 3>>& triangles() const { return triangles_; }
  int NumDelaunayTriangles() const { return num_delaunay_triangles_; }

  // For each view, the other views that can be blended with it at a pixel (the views of the
  // triangles it is a corner of, extension ring included, or its neighbours along a line), sorted;
  // witnesses (ViewSlots) are not among them.
  std::vector<std::vector<int>> SlotNeighbours() const;

  // The weights at point q of the mesh plane. `hint` (may be null): the triangle to start the
  // search from, updated to the one found (or -1 outside the mesh).
  ViewSlots WeightsAt(const Eigen::Vector2d& q, int* hint = nullptr) const;
  // The point of the mesh plane where pixel (x, y)'s line meets it (section 3).
  Eigen::Vector2d PlanePointOfPixel(const CameraModel& camera, const Rigid3& cam_from_world, double x, double y) const;
  // Weights for every pixel of a pinhole camera, row-major (width * height entries), rows in
  // parallel; raised to `exponent` (FlattenViewingWeights) as each band of rows is made.
  void ComputeWeights(const CameraModel& camera,
                      const Rigid3& cam_from_world,
                      std::vector<ViewSlots>* slots,
                      double exponent = 1.0) const;

 private:
  struct Barycentric {  // lambda_1,2 = inverse * (q - p0), lambda_0 = 1 - lambda_1 - lambda_2
    Eigen::Vector2d p0;
    Eigen::Matrix2d inverse;
  };

  void BuildTriangleData();
  // The triangle holding q (walking from `hint`), or -1 outside the mesh.
  int Locate(const Eigen::Vector2d& q, int hint) const;
  std::array<double, 3> Coordinates(int triangle, const Eigen::Vector2d& q) const;
  ViewSlots TriangleWeights(int triangle, const Eigen::Vector2d& q) const;
  // The outer edge nearest q (-1 without any) and the parameter in [0, 1] of its point nearest q;
  // only the edges `among` (ascending) where given.
  std::pair<int, double> NearestOuterEdge(const Eigen::Vector2d& q, const std::vector<int>* among = nullptr) const;
  ViewSlots OutsideWeights(const Eigen::Vector2d& q, const std::vector<int>* among = nullptr) const;
  // Where q (outside the mesh) finds its nearest point: the outer edge's index when inside that
  // edge, else -2 - v for the outer vertex v. On a convex outline each such region is convex
  // (an intersection of half-planes), so ComputeWeights may fill a tile whose corners share one.
  int OutsideRegion(const Eigen::Vector2d& q) const;
  // Whether every point of the convex quadrilateral `quad` (corners in order around it), whose
  // corners lie outside the mesh in `region`, does too. Always on a convex outline; on another,
  // when the quadrilateral misses every triangle and the region's distance, largest at a corner,
  // stays below every other outer edge's least distance to it. For a vertex's region there,
  // `vertex_edges` receives the outer edges from the vertex (ascending), else it is left empty.
  bool OutsideRegionHolds(int region, const std::array<Eigen::Vector2d, 4>& quad, std::vector<int>* vertex_edges) const;
  ViewSlots LineWeights(const Eigen::Vector2d& q) const;
  // The view, other than `views` (-1: none), whose vertex lies nearest `at`; -1 when there is none.
  int NearestOtherView(const Eigen::Vector2d& at, const std::array<int, 3>& views) const;

  Kind kind_ = Kind::kPoint;
  int num_views_ = 0;
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal_ = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d axis_u_ = Eigen::Vector3d::UnitX();
  Eigen::Vector3d axis_v_ = Eigen::Vector3d::UnitY();
  std::vector<Vertex> vertices_;
  std::vector<std::array<int, 3>> triangles_;
  int num_delaunay_triangles_ = 0;
  std::vector<Barycentric> barycentric_;         // per triangle
  std::vector<std::array<int, 3>> neighbours_;   // per triangle: across the edge opposite vertex k
  std::vector<std::array<int, 2>> outer_edges_;  // vertex pairs on the extended mesh's boundary
  std::vector<int> outer_edge_witness_;          // per outer edge: its witness view (ViewSlots), or -1
  std::vector<int> triangle_witness_;            // per triangle with fewer than three views: its witness, or -1
  std::vector<int> line_witness_;                // kLine: per pair of neighbours along it, their witness
  bool outline_convex_ = false;                  // every outer vertex on or inside every outer edge
  std::vector<int> line_order_;                  // kLine: views sorted along axis_u
};

// Raises every slot's weight to `exponent` in (0, 1] and renormalises the three to sum 1
// (ALGORITHM.md section 3): 1 leaves the barycentric weights; 0.5 (sqrt) makes the views share a
// pixel more evenly. Weights of 0 stay 0 and a lone view keeps 1, so the weights stay continuous
// over the image and along a camera path. Rows in parallel.
void FlattenViewingWeights(double exponent, std::vector<ViewSlots>* slots);
// The same over slots [begin, end), on the calling thread.
void FlattenSlots(double exponent, ViewSlots* begin, ViewSlots* end);

}  // namespace px::render
