#include "pipeline/render/view_mesh.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <functional>
#include <limits>
#include <map>
#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <utility>
#include <vector>

namespace px::render {
namespace {

// Below this (metres) two centres count as one point, and a sequence of centres as one.
constexpr double kSameCentreM = 1e-9;
// Second eigenvalue of the centres' scatter below this fraction of the first: collinear.
constexpr double kCollinearRatio = 1e-6;
// Barycentric coordinates down to -kInsideTolerance count as inside (a point on an edge).
constexpr double kInsideTolerance = 1e-9;

double Cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

// Sums the weights of repeated views into one slot (a boundary vertex and its duplicate).
ViewSlots Merge(std::array<int, 3> views, std::array<double, 3> weights) {
  ViewSlots slots;
  int used = 0;
  for (int k = 0; k < 3; ++k) {
    if (views[k] < 0) continue;
    const double w = std::max(0.0, weights[k]);
    int found = -1;
    for (int j = 0; j < used; ++j) {
      if (slots.view[j] == views[k]) found = j;
    }
    if (found >= 0) {
      slots.weight[found] += static_cast<float>(w);
    } else {
      slots.view[used] = static_cast<uint8_t>(views[k]);
      slots.weight[used] = static_cast<float>(w);
      ++used;
    }
  }
  float sum = 0;
  for (int k = 0; k < used; ++k) sum += slots.weight[k];
  if (sum > 0) {
    for (int k = 0; k < used; ++k) slots.weight[k] /= sum;
  } else if (used > 0) {
    slots.weight[0] = 1;
  }
  return slots;
}

// `slots` with `witness` (a view, or -1 for none) in its first free slot at weight 0.
ViewSlots WithWitness(ViewSlots slots, int witness) {
  if (witness < 0) return slots;
  for (int k = 0; k < 3; ++k) {
    if (slots.view[k] == witness) return slots;
    if (slots.view[k] == ViewSlots::kNone) {
      slots.view[k] = static_cast<uint8_t>(witness);
      slots.witness = static_cast<uint8_t>(k);
      slots.weight[k] = 0;
      return slots;
    }
  }
  return slots;
}

// Subdiv2D's triangles on `scaled` points whose outer virtual vertices sit `outer` units from
// the frame of the points: the real triangles (virtual vertices dropped), counter-clockwise.
std::vector<std::array<int, 3>> SubdivTriangles(const std::vector<cv::Point2f>& scaled,
                                                const std::vector<Eigen::Vector2d>& positions,
                                                int outer) {
  cv::Subdiv2D subdiv(cv::Rect(-10, -10, outer, outer));
  std::map<std::pair<float, float>, int> index_of;
  for (size_t i = 0; i < scaled.size(); ++i) {
    if (index_of.emplace(std::make_pair(scaled[i].x, scaled[i].y), static_cast<int>(i)).second)
      subdiv.insert(scaled[i]);
  }
  std::vector<cv::Vec6f> list;
  subdiv.getTriangleList(list);
  std::vector<std::array<int, 3>> triangles;
  for (const cv::Vec6f& t : list) {
    std::array<int, 3> tri{};
    bool real = true;
    for (int k = 0; k < 3; ++k) {
      const auto it = index_of.find(std::make_pair(t[2 * k], t[2 * k + 1]));
      if (it == index_of.end()) {
        real = false;  // one of Subdiv2D's outer virtual vertices
        break;
      }
      tri[k] = it->second;
    }
    if (!real) continue;
    const Eigen::Vector2d& a = positions[tri[0]];
    const double area = Cross2(positions[tri[1]] - a, positions[tri[2]] - a);
    if (std::abs(area) < 1e-18) continue;
    if (area < 0) std::swap(tri[1], tri[2]);
    triangles.push_back(tri);
  }
  return triangles;
}

// The Delaunay triangles of non-collinear points, by cv::Subdiv2D on coordinates scaled to about
// a thousand units (it stores float). Its outer virtual vertices are at a finite distance, so a
// thin triangle along the hull has a circumcircle holding one and is left out. That is kept where
// other triangles remain: the extension ring then covers the hull's edge, and renders better than
// the slivers would (LLFF fern: 24.92 dB, 24.81 with the whole hull). Centres nearly on a line
// (a hand-held sweep) can have nothing but slivers: then the outer vertices move out a
// hundredfold at a time until the triangles cover the points' convex hull.
StatusOr<std::vector<std::array<int, 3>>> DelaunayTriangles(const std::vector<Eigen::Vector2d>& positions) {
  Eigen::Vector2d low = positions[0], high = low;
  for (const Eigen::Vector2d& p : positions) {
    low = low.cwiseMin(p);
    high = high.cwiseMax(p);
  }
  const double scale = 1000.0 / std::max((high - low).maxCoeff(), 1e-12);
  std::vector<cv::Point2f> scaled;
  for (const Eigen::Vector2d& p : positions) {
    scaled.emplace_back(static_cast<float>((p.x() - low.x()) * scale), static_cast<float>((p.y() - low.y()) * scale));
  }
  std::vector<std::array<int, 3>> triangles = SubdivTriangles(scaled, positions, 1021);
  if (!triangles.empty()) return triangles;
  std::vector<cv::Point2f> hull;
  cv::convexHull(scaled, hull);
  const double hull_area = std::abs(cv::contourArea(hull)) / (scale * scale);
  for (int outer = 102100; outer <= 102100000; outer *= 100) {
    triangles = SubdivTriangles(scaled, positions, outer);
    double area = 0;
    for (const auto& tri : triangles)
      area += Cross2(positions[tri[1]] - positions[tri[0]], positions[tri[2]] - positions[tri[0]]) / 2;
    if (!triangles.empty() && area >= (1 - 1e-4) * hull_area) return triangles;
  }
  if (triangles.empty()) {
    return InternalError("view mesh: Delaunay triangulation of " + std::to_string(positions.size()) +
                         " non-collinear centres gave no triangle");
  }
  return triangles;
}

}  // namespace

StatusOr<ViewMesh> ViewMesh::Build(const std::vector<Eigen::Vector3d>& centres_in_world,
                                   const std::vector<Eigen::Matrix3d>& world_from_cam_rotations) {
  const int n = static_cast<int>(centres_in_world.size());
  if (n == 0) return InvalidArgumentError("view mesh: no views");
  if (n > kMaxViews) {
    return InvalidArgumentError("view mesh: " + std::to_string(n) + " views, at most " + std::to_string(kMaxViews));
  }
  if (world_from_cam_rotations.size() != centres_in_world.size()) {
    return InvalidArgumentError("view mesh: " + std::to_string(world_from_cam_rotations.size()) + " rotations for " +
                                std::to_string(n) + " centres");
  }
  for (int i = 0; i < n; ++i) {
    if (!centres_in_world[i].allFinite() || !world_from_cam_rotations[i].allFinite()) {
      return InvalidArgumentError("view mesh: view " + std::to_string(i) + " has a pose that is not finite");
    }
  }
  ViewMesh mesh;
  mesh.num_views_ = n;
  Eigen::Vector3d mean_axis = Eigen::Vector3d::Zero(), mean_x = Eigen::Vector3d::Zero();
  for (int i = 0; i < n; ++i) {
    mesh.origin_ += centres_in_world[i] / n;
    mean_axis += world_from_cam_rotations[i].col(2);
    mean_x += world_from_cam_rotations[i].col(0);
  }
  if (mean_axis.norm() < 1e-9) mean_axis = Eigen::Vector3d::UnitZ();
  mean_axis.normalize();
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  double spread = 0;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d d = centres_in_world[i] - mesh.origin_;
    scatter += d * d.transpose();
    spread = std::max(spread, d.norm());
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(scatter);  // eigenvalues ascending
  const Eigen::Vector3d eigenvalues = eigen.eigenvalues();

  // In-plane x axis: the mean camera x axis with the normal's share removed (or any orthogonal one).
  const auto set_axes = [&](const Eigen::Vector3d& normal, const Eigen::Vector3d& preferred_u) {
    mesh.normal_ = normal.normalized();
    Eigen::Vector3d u = preferred_u - preferred_u.dot(mesh.normal_) * mesh.normal_;
    if (u.norm() < 1e-9) u = mesh.normal_.unitOrthogonal();
    mesh.axis_u_ = u.normalized();
    mesh.axis_v_ = mesh.normal_.cross(mesh.axis_u_);
  };

  if (n == 1 || spread < kSameCentreM) {
    mesh.kind_ = Kind::kPoint;
    set_axes(mean_axis, mean_x);
    mesh.vertices_.push_back({Eigen::Vector2d::Zero(), 0});
    return mesh;
  }
  if (eigenvalues(1) < kCollinearRatio * eigenvalues(2)) {
    // Centres on a line: the plane holds the line and is as square to the views as it can be.
    Eigen::Vector3d line = eigen.eigenvectors().col(2);
    if (line.dot(mean_x) < 0) line = -line;
    Eigen::Vector3d normal = mean_axis - mean_axis.dot(line) * line;
    if (normal.norm() < 1e-9) normal = line.unitOrthogonal();
    set_axes(normal, line);
    mesh.kind_ = Kind::kLine;
    for (int i = 0; i < n; ++i) mesh.vertices_.push_back({mesh.ToPlane(centres_in_world[i]), i});
    mesh.line_order_.resize(n);
    for (int i = 0; i < n; ++i) mesh.line_order_[i] = i;
    std::sort(mesh.line_order_.begin(), mesh.line_order_.end(), [&](int a, int b) {
      return mesh.vertices_[a].position.x() < mesh.vertices_[b].position.x();
    });
    for (int i = 0; i + 1 < n; ++i) {
      const int a = mesh.line_order_[i], b = mesh.line_order_[i + 1];
      mesh.line_witness_.push_back(
          mesh.NearestOtherView(0.5 * (mesh.vertices_[a].position + mesh.vertices_[b].position), {a, b, -1}));
    }
    return mesh;
  }
  Eigen::Vector3d normal = eigen.eigenvectors().col(0);
  if (normal.dot(mean_axis) < 0) normal = -normal;
  set_axes(normal, mean_x);
  for (int i = 0; i < n; ++i) mesh.vertices_.push_back({mesh.ToPlane(centres_in_world[i]), i});

  std::vector<Eigen::Vector2d> positions;
  for (const Vertex& v : mesh.vertices_) positions.push_back(v.position);
  PX_ASSIGN_OR_RETURN(mesh.triangles_, DelaunayTriangles(positions));
  mesh.num_delaunay_triangles_ = static_cast<int>(mesh.triangles_.size());

  // Boundary edges (one triangle each), oriented as in their counter-clockwise triangle: the
  // outside lies to their right.
  std::map<std::pair<int, int>, int> edge_count;
  for (const auto& tri : mesh.triangles_) {
    for (int k = 0; k < 3; ++k) {
      const int a = tri[k], b = tri[(k + 1) % 3];
      ++edge_count[{std::min(a, b), std::max(a, b)}];
    }
  }
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (int i = 0; i < n; ++i) centroid += mesh.vertices_[i].position / n;
  std::map<int, int> duplicate_of;
  const auto duplicate = [&](int i) {
    auto it = duplicate_of.find(i);
    if (it != duplicate_of.end()) return it->second;
    const int index = static_cast<int>(mesh.vertices_.size());
    mesh.vertices_.push_back({centroid + 4.0 * (mesh.vertices_[i].position - centroid), mesh.vertices_[i].view});
    duplicate_of[i] = index;
    return index;
  };
  for (int t = 0; t < mesh.num_delaunay_triangles_; ++t) {
    const std::array<int, 3> tri = mesh.triangles_[t];
    for (int k = 0; k < 3; ++k) {
      const int a = tri[k], b = tri[(k + 1) % 3];
      if (edge_count[{std::min(a, b), std::max(a, b)}] != 1) continue;
      const int a2 = duplicate(a), b2 = duplicate(b);
      // The ring quad (a, b, b', a') lies to the right of a->b: (a, b', b) and (a, a', b') are
      // counter-clockwise.
      mesh.triangles_.push_back({a, b2, b});
      mesh.triangles_.push_back({a, a2, b2});
    }
  }
  for (auto& tri : mesh.triangles_) {
    const Eigen::Vector2d& a = mesh.vertices_[tri[0]].position;
    if (Cross2(mesh.vertices_[tri[1]].position - a, mesh.vertices_[tri[2]].position - a) < 0) std::swap(tri[1], tri[2]);
  }
  mesh.kind_ = Kind::kTriangles;
  mesh.BuildTriangleData();
  return mesh;
}

void ViewMesh::BuildTriangleData() {
  const int count = static_cast<int>(triangles_.size());
  barycentric_.resize(count);
  neighbours_.assign(count, {-1, -1, -1});
  std::map<std::pair<int, int>, std::pair<int, int>> edge_owner;  // edge -> (triangle, opposite slot)
  for (int t = 0; t < count; ++t) {
    const auto& tri = triangles_[t];
    const Eigen::Vector2d& p0 = vertices_[tri[0]].position;
    Eigen::Matrix2d m;
    m.col(0) = vertices_[tri[1]].position - p0;
    m.col(1) = vertices_[tri[2]].position - p0;
    barycentric_[t] = {p0, m.inverse()};
    for (int k = 0; k < 3; ++k) {
      // The edge opposite vertex k.
      const int a = tri[(k + 1) % 3], b = tri[(k + 2) % 3];
      const std::pair<int, int> key{std::min(a, b), std::max(a, b)};
      auto it = edge_owner.find(key);
      if (it == edge_owner.end()) {
        edge_owner[key] = {t, k};
      } else {
        neighbours_[t][k] = it->second.first;
        neighbours_[it->second.first][it->second.second] = t;
      }
    }
  }
  // Witnesses (ViewSlots) where two views are blended: the ring's triangles and the outer edges
  // carry a hull edge's two views; its Delaunay triangle's third corner witnesses them.
  std::map<std::pair<int, int>, int> hull_edge_witness;
  for (int t = 0; t < num_delaunay_triangles_; ++t) {
    for (int k = 0; k < 3; ++k) {
      const int a = vertices_[triangles_[t][(k + 1) % 3]].view, b = vertices_[triangles_[t][(k + 2) % 3]].view;
      hull_edge_witness[{std::min(a, b), std::max(a, b)}] = vertices_[triangles_[t][k]].view;
    }
  }
  // The witness of a triangle or edge carrying exactly two views among `views` (-1: no view).
  const auto witness_of = [&](const std::array<int, 3>& views) {
    int a = -1, b = -1;
    for (const int view : views) {
      if (view < 0 || view == a || view == b) continue;
      if (a < 0) {
        a = view;
      } else if (b < 0) {
        b = view;
      } else {
        return -1;  // three views
      }
    }
    if (b < 0) return -1;
    const auto it = hull_edge_witness.find({std::min(a, b), std::max(a, b)});
    if (it != hull_edge_witness.end()) return it->second;
    return NearestOtherView(0.5 * (vertices_[a].position + vertices_[b].position), {a, b, -1});
  };
  triangle_witness_.assign(count, -1);
  for (int t = 0; t < count; ++t) {
    triangle_witness_[t] = witness_of(
        {vertices_[triangles_[t][0]].view, vertices_[triangles_[t][1]].view, vertices_[triangles_[t][2]].view});
  }
  outer_edges_.clear();
  outer_edge_witness_.clear();
  for (int t = 0; t < count; ++t) {
    for (int k = 0; k < 3; ++k) {
      if (neighbours_[t][k] >= 0) continue;
      const int a = triangles_[t][(k + 1) % 3], b = triangles_[t][(k + 2) % 3];
      outer_edges_.push_back({a, b});
      outer_edge_witness_.push_back(witness_of({vertices_[a].view, vertices_[b].view, -1}));
    }
  }
  // Counter-clockwise triangles leave the outside to the right of their outer edges.
  outline_convex_ = !outer_edges_.empty();
  for (const auto& edge : outer_edges_) {
    const Eigen::Vector2d& a = vertices_[edge[0]].position;
    const Eigen::Vector2d ab = vertices_[edge[1]].position - a;
    for (const auto& other : outer_edges_) {
      const Eigen::Vector2d aq = vertices_[other[0]].position - a;
      if (Cross2(ab, aq) < -1e-9 * ab.squaredNorm() - 1e-12 * aq.squaredNorm()) outline_convex_ = false;
    }
  }
}

int ViewMesh::NearestOtherView(const Eigen::Vector2d& at, const std::array<int, 3>& views) const {
  int nearest = -1;
  double best = std::numeric_limits<double>::infinity();
  for (int i = 0; i < std::min<int>(num_views_, static_cast<int>(vertices_.size())); ++i) {
    const int view = vertices_[i].view;
    if (view == views[0] || view == views[1] || view == views[2]) continue;
    const double d2 = (vertices_[i].position - at).squaredNorm();
    if (d2 < best) {
      best = d2;
      nearest = view;
    }
  }
  return nearest;
}

Eigen::Vector2d ViewMesh::ToPlane(const Eigen::Vector3d& point_in_world) const {
  const Eigen::Vector3d d = point_in_world - origin_;
  return {d.dot(axis_u_), d.dot(axis_v_)};
}

std::vector<std::vector<int>> ViewMesh::SlotNeighbours() const {
  std::vector<std::vector<int>> neighbours(num_views_);
  const auto link = [&](int a, int b) {
    if (a == b) return;
    neighbours[a].push_back(b);
    neighbours[b].push_back(a);
  };
  if (kind_ == Kind::kLine) {
    for (size_t i = 0; i + 1 < line_order_.size(); ++i) link(line_order_[i], line_order_[i + 1]);
  } else if (kind_ == Kind::kTriangles) {
    for (const std::array<int, 3>& t : triangles_) {
      for (int k = 0; k < 3; ++k) link(vertices_[t[k]].view, vertices_[t[(k + 1) % 3]].view);
    }
  }
  for (std::vector<int>& list : neighbours) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
  }
  return neighbours;
}

ViewSlots ViewMesh::LineWeights(const Eigen::Vector2d& q) const {
  const int first = line_order_.front(), last = line_order_.back();
  const double x = q.x();
  if (x <= vertices_[first].position.x()) return Merge({first, -1, -1}, {1, 0, 0});
  if (x >= vertices_[last].position.x()) return Merge({last, -1, -1}, {1, 0, 0});
  for (size_t i = 0; i + 1 < line_order_.size(); ++i) {
    const int a = line_order_[i], b = line_order_[i + 1];
    const double xa = vertices_[a].position.x(), xb = vertices_[b].position.x();
    if (x > xb) continue;
    const double span = xb - xa;
    const double tb = span > 0 ? (x - xa) / span : 0.0;
    return WithWitness(Merge({a, b, -1}, {1 - tb, tb, 0}), line_witness_[i]);
  }
  return Merge({last, -1, -1}, {1, 0, 0});
}

std::pair<int, double> ViewMesh::NearestOuterEdge(const Eigen::Vector2d& q, const std::vector<int>* among) const {
  double best = std::numeric_limits<double>::infinity();
  std::pair<int, double> nearest{-1, 0.0};
  const int count = among != nullptr ? static_cast<int>(among->size()) : static_cast<int>(outer_edges_.size());
  for (int i = 0; i < count; ++i) {
    const int e = among != nullptr ? (*among)[i] : i;
    const Eigen::Vector2d& a = vertices_[outer_edges_[e][0]].position;
    const Eigen::Vector2d ab = vertices_[outer_edges_[e][1]].position - a;
    const double length2 = ab.squaredNorm();
    const double t = length2 > 0 ? std::clamp((q - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
    const double d2 = (a + t * ab - q).squaredNorm();
    if (d2 < best) {
      best = d2;
      nearest = {e, t};
    }
  }
  return nearest;
}

ViewSlots ViewMesh::OutsideWeights(const Eigen::Vector2d& q, const std::vector<int>* among) const {
  const auto [e, t] = NearestOuterEdge(q, among);
  if (e < 0) return ViewSlots{};
  return WithWitness(Merge({vertices_[outer_edges_[e][0]].view, vertices_[outer_edges_[e][1]].view, -1}, {1 - t, t, 0}),
                     outer_edge_witness_[e]);
}

int ViewMesh::OutsideRegion(const Eigen::Vector2d& q) const {
  const auto [e, t] = NearestOuterEdge(q);
  if (e < 0) return -1;
  return t <= 0 ? -2 - outer_edges_[e][0] : t >= 1 ? -2 - outer_edges_[e][1] : e;
}

namespace {

// Distance from p to the segment [a, b].
double PointSegmentDistance(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double length2 = ab.squaredNorm();
  const double t = length2 > 0 ? std::clamp((p - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

// Whether the segments [a, b] and [c, d] touch.
bool SegmentsTouch(const Eigen::Vector2d& a,
                   const Eigen::Vector2d& b,
                   const Eigen::Vector2d& c,
                   const Eigen::Vector2d& d) {
  const double d1 = Cross2(b - a, c - a), d2 = Cross2(b - a, d - a);
  const double d3 = Cross2(d - c, a - c), d4 = Cross2(d - c, b - c);
  return d1 * d2 <= 0 && d3 * d4 <= 0;
}

// Least distance from the segment [a, b] to the convex quadrilateral `quad` (0 when they touch or
// the segment lies inside).
double SegmentQuadDistance(const Eigen::Vector2d& a,
                           const Eigen::Vector2d& b,
                           const std::array<Eigen::Vector2d, 4>& quad) {
  bool a_inside = true;
  double sign = 0;
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector2d& p = quad[k];
    const Eigen::Vector2d& q = quad[(k + 1) % 4];
    if (SegmentsTouch(a, b, p, q)) return 0;
    const double side = Cross2(q - p, a - p);
    if (side * sign < 0) a_inside = false;
    if (side != 0) sign = side;
  }
  if (a_inside) return 0;
  double least = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 4; ++k) {
    least = std::min({least,
                      PointSegmentDistance(quad[k], a, b),
                      PointSegmentDistance(a, quad[k], quad[(k + 1) % 4]),
                      PointSegmentDistance(b, quad[k], quad[(k + 1) % 4])});
  }
  return least;
}

// The gap between two axis-aligned boxes (0 when they overlap), a lower bound on the distance
// between anything inside them.
double BoxGap(const Eigen::AlignedBox2d& a, const Eigen::AlignedBox2d& b) {
  const Eigen::Vector2d gap = (a.min() - b.max()).cwiseMax(b.min() - a.max()).cwiseMax(0.0);
  return gap.norm();
}

template <size_t N>
Eigen::AlignedBox2d BoxOf(const std::array<Eigen::Vector2d, N>& points) {
  Eigen::AlignedBox2d box;
  for (const Eigen::Vector2d& p : points) box.extend(p);
  return box;
}

// Whether the triangle and the convex quadrilateral lie apart by more than `margin` along some
// edge's normal (separating axes: two convex polygons are disjoint exactly when one separates).
bool Separated(const std::array<Eigen::Vector2d, 3>& triangle,
               const std::array<Eigen::Vector2d, 4>& quad,
               double margin) {
  const auto apart_along = [&](const Eigen::Vector2d& edge) {
    const Eigen::Vector2d axis(-edge.y(), edge.x());
    const double norm = axis.norm();
    if (!(norm > 0)) return false;
    double t_low = INFINITY, t_high = -INFINITY, q_low = INFINITY, q_high = -INFINITY;
    for (const Eigen::Vector2d& p : triangle) {
      t_low = std::min(t_low, axis.dot(p) / norm);
      t_high = std::max(t_high, axis.dot(p) / norm);
    }
    for (const Eigen::Vector2d& p : quad) {
      q_low = std::min(q_low, axis.dot(p) / norm);
      q_high = std::max(q_high, axis.dot(p) / norm);
    }
    return t_high + margin < q_low || q_high + margin < t_low;
  };
  for (int k = 0; k < 3; ++k) {
    if (apart_along(triangle[(k + 1) % 3] - triangle[k])) return true;
  }
  for (int k = 0; k < 4; ++k) {
    if (apart_along(quad[(k + 1) % 4] - quad[k])) return true;
  }
  return false;
}

}  // namespace

bool ViewMesh::OutsideRegionHolds(int region,
                                  const std::array<Eigen::Vector2d, 4>& quad,
                                  std::vector<int>* vertex_edges) const {
  vertex_edges->clear();
  if (outline_convex_) return true;
  // The region's own distance is convex over the quadrilateral, so largest at a corner; along an
  // edge's inside (0 < t < 1 at every corner, t being affine) it is the distance to its line.
  double own = 0;
  const auto parameter = [&](const std::array<int, 2>& edge, const Eigen::Vector2d& q) {
    const Eigen::Vector2d& a = vertices_[edge[0]].position;
    const Eigen::Vector2d ab = vertices_[edge[1]].position - a;
    return (q - a).dot(ab) / ab.squaredNorm();
  };
  const int vertex = region <= -2 ? -2 - region : -1;
  for (const Eigen::Vector2d& q : quad) {
    if (vertex >= 0) {
      own = std::max(own, (q - vertices_[vertex].position).norm());
    } else {
      const double t = parameter(outer_edges_[region], q);
      if (!(t > 0 && t < 1)) return false;
      own = std::max(own,
                     PointSegmentDistance(
                         q, vertices_[outer_edges_[region][0]].position, vertices_[outer_edges_[region][1]].position));
    }
  }
  const Eigen::AlignedBox2d quad_box = BoxOf<4>(quad);
  // Every other edge lies farther, by more than rounding.
  const double farther = own * (1 + 1e-9) + 1e-300;
  for (size_t e = 0; e < outer_edges_.size(); ++e) {
    const std::array<int, 2>& edge = outer_edges_[e];
    if (static_cast<int>(e) == region) continue;
    if (edge[0] == vertex || edge[1] == vertex) {
      // An edge from the vertex: its nearest point must stay the vertex, beyond its end.
      for (const Eigen::Vector2d& q : quad) {
        const double t = parameter(edge, q);
        if (edge[0] == vertex ? !(t < 0) : !(t > 1)) return false;
      }
      vertex_edges->push_back(static_cast<int>(e));
      continue;
    }
    const Eigen::Vector2d& a = vertices_[edge[0]].position;
    const Eigen::Vector2d& b = vertices_[edge[1]].position;
    if (BoxGap(quad_box, BoxOf<2>({a, b})) > farther) continue;
    if (!(SegmentQuadDistance(a, b, quad) > farther)) return false;
  }
  // Outside every triangle, by more than the tolerance that counts a point on an edge as inside
  // (ring triangles along a thin mesh may overlap, so the outer edges alone do not bound it).
  for (size_t t = 0; t < triangles_.size(); ++t) {
    const std::array<Eigen::Vector2d, 3> corners = {vertices_[triangles_[t][0]].position,
                                                    vertices_[triangles_[t][1]].position,
                                                    vertices_[triangles_[t][2]].position};
    const double margin = 1e-6 * std::max((corners[1] - corners[0]).norm(), (corners[2] - corners[0]).norm());
    if (BoxGap(quad_box, BoxOf<3>(corners)) > margin) continue;
    if (!Separated(corners, quad, margin)) return false;
  }
  return true;
}

std::array<double, 3> ViewMesh::Coordinates(int triangle, const Eigen::Vector2d& q) const {
  const Barycentric& b = barycentric_[triangle];
  const Eigen::Vector2d l12 = b.inverse * (q - b.p0);
  return {1 - l12.x() - l12.y(), l12.x(), l12.y()};
}

int ViewMesh::Locate(const Eigen::Vector2d& q, int hint) const {
  const int count = static_cast<int>(triangles_.size());
  int t = (hint >= 0 && hint < count) ? hint : 0;
  // Walk towards q across the edge of the most negative coordinate; a walk that takes more steps
  // than there are triangles is cycling (the ring is not Delaunay), and the scan below settles it.
  for (int step = 0; step <= count; ++step) {
    const std::array<double, 3> l = Coordinates(t, q);
    int worst = 0;
    for (int k = 1; k < 3; ++k) {
      if (l[k] < l[worst]) worst = k;
    }
    if (l[worst] >= -kInsideTolerance) return t;
    const int next = neighbours_[t][worst];
    if (next < 0) break;  // across the outer boundary: q may be outside the mesh
    t = next;
  }
  for (int s = 0; s < count; ++s) {
    const std::array<double, 3> l = Coordinates(s, q);
    if (l[0] >= -kInsideTolerance && l[1] >= -kInsideTolerance && l[2] >= -kInsideTolerance) return s;
  }
  return -1;
}

ViewSlots ViewMesh::TriangleWeights(int triangle, const Eigen::Vector2d& q) const {
  const auto& tri = triangles_[triangle];
  return WithWitness(
      Merge({vertices_[tri[0]].view, vertices_[tri[1]].view, vertices_[tri[2]].view}, Coordinates(triangle, q)),
      triangle_witness_[triangle]);
}

ViewSlots ViewMesh::WeightsAt(const Eigen::Vector2d& q, int* hint) const {
  if (kind_ == Kind::kPoint) return Merge({vertices_[0].view, -1, -1}, {1, 0, 0});
  if (kind_ == Kind::kLine) return LineWeights(q);
  const int t = Locate(q, hint != nullptr ? *hint : -1);
  if (hint != nullptr) *hint = t;
  return t >= 0 ? TriangleWeights(t, q) : OutsideWeights(q);
}

namespace {

// Pixel (x, y) -> plane point, as q = q_o - h N(x, y) / s(x, y) with N and s linear in (x, y, 1)
// (ALGORITHM.md section 3).
struct PixelToPlane {
  Eigen::Matrix<double, 2, 3> numerator;  // axes^T R^T K^-1
  Eigen::RowVector3d denominator;         // n^T R^T K^-1
  Eigen::Matrix3d k_inverse;
  Eigen::Vector2d q_centre;  // the camera centre's projection onto the plane
  double height = 0;         // n . (o - m)

  Eigen::Vector2d At(double x, double y) const {
    const Eigen::Vector3d pixel(x, y, 1.0);
    const double s = denominator.dot(pixel);
    const double ray_norm = (k_inverse * pixel).norm();
    if (std::abs(s) <= 1e-9 * ray_norm) return q_centre;
    return q_centre - (height / s) * (numerator * pixel);
  }
};

PixelToPlane MakePixelToPlane(const ViewMesh& mesh, const CameraModel& camera, const Rigid3& cam_from_world) {
  PixelToPlane map;
  map.k_inverse = camera.K().inverse();
  const Eigen::Matrix3d world_from_cam = cam_from_world.RotationMatrix().transpose();
  const Eigen::Matrix3d ray = world_from_cam * map.k_inverse;
  map.numerator.row(0) = mesh.axis_u().transpose() * ray;
  map.numerator.row(1) = mesh.axis_v().transpose() * ray;
  map.denominator = mesh.normal().transpose() * ray;
  const Eigen::Vector3d centre = CameraCentre(cam_from_world);
  map.height = mesh.normal().dot(centre - mesh.origin());
  map.q_centre = mesh.ToPlane(centre);
  return map;
}

}  // namespace

Eigen::Vector2d ViewMesh::PlanePointOfPixel(const CameraModel& camera,
                                            const Rigid3& cam_from_world,
                                            double x,
                                            double y) const {
  return MakePixelToPlane(*this, camera, cam_from_world).At(x, y);
}

void ViewMesh::ComputeWeights(const CameraModel& camera,
                              const Rigid3& cam_from_world,
                              std::vector<ViewSlots>* slots,
                              double exponent) const {
  const int width = camera.width, height = camera.height;
  slots->resize(static_cast<size_t>(width) * height);
  if (kind_ == Kind::kPoint) {
    std::fill(slots->begin(), slots->end(), WeightsAt(Eigen::Vector2d::Zero()));
    FlattenViewingWeights(exponent, slots);
    return;
  }
  const PixelToPlane map = MakePixelToPlane(*this, camera, cam_from_world);
  constexpr int kTile = 16;
  // Tiles straddling a triangle edge are split down to this size before going pixel by pixel.
  constexpr int kMinTile = 2;
  const int tiles_x = (width + kTile - 1) / kTile;
  const int tiles_y = (height + kTile - 1) / kTile;
  // Pixels [x0, x1] x [y0, y1], all outside the mesh in `region` (OutsideRegion): a vertex's view
  // alone, or an outer edge's two views at t = alpha + (r . pixel) / (s . pixel) along it, as
  // OutsideWeights would give them pixel by pixel.
  const auto fill_outside = [&](int region, int x0, int y0, int x1, int y1) {
    if (region <= -2) {
      const ViewSlots vertex = Merge({vertices_[-2 - region].view, -1, -1}, {1, 0, 0});
      for (int y = y0; y <= y1; ++y)
        std::fill_n(slots->data() + static_cast<size_t>(y) * width + x0, x1 - x0 + 1, vertex);
      return;
    }
    const auto& edge = outer_edges_[region];
    const Eigen::Vector2d& a = vertices_[edge[0]].position;
    const Eigen::Vector2d ab = vertices_[edge[1]].position - a;
    const double length2 = ab.squaredNorm();
    const double alpha = (map.q_centre - a).dot(ab) / length2;
    const Eigen::RowVector3d r = -map.height / length2 * (ab.transpose() * map.numerator);
    const ViewSlots pattern = WithWitness(Merge({vertices_[edge[0]].view, vertices_[edge[1]].view, -1}, {0.5, 0.5, 0}),
                                          outer_edge_witness_[region]);
    const int slot_a = 0, slot_b = pattern.view[0] == vertices_[edge[1]].view ? 0 : 1;
    const double sx = map.denominator(0), s_y = map.denominator(1), s1 = map.denominator(2);
    for (int y = y0; y <= y1; ++y) {
      ViewSlots* row = slots->data() + static_cast<size_t>(y) * width;
      const double s_row = s_y * y + s1, r_row = r(1) * y + r(2);
      for (int x = x0; x <= x1; ++x) {
        const double t = std::clamp(alpha + (r(0) * x + r_row) / (sx * x + s_row), 0.0, 1.0);
        ViewSlots out;
        out.view = pattern.view;
        out.witness = pattern.witness;
        out.weight[slot_a] += static_cast<float>(1 - t);
        out.weight[slot_b] += static_cast<float>(t);
        row[x] = out;
      }
    }
  };
  cv::parallel_for_(cv::Range(0, tiles_y), [&](const cv::Range& tile_rows) {
    int hint = -1;
    // Pixels [x0, x1] x [y0, y1].
    const std::function<void(int, int, int, int)> fill = [&](int x0, int y0, int x1, int y1) {
      // Fast paths: the tile's four corners lie in one triangle, or outside the mesh in one
      // region of its nearest outer edge or vertex (on a convex outline; on another where
      // OutsideRegionHolds), and no pixel's line is near parallel to the plane, so (the map being
      // projective and the regions convex) every pixel does, and its weights are ratios of linear
      // functions of (x, y).
      int triangle = -2;  // the corners' triangle, -1 outside the mesh
      int outside = 0;    // their OutsideRegion when outside
      bool regular = kind_ == Kind::kTriangles;
      double s_sign = 0;
      std::array<Eigen::Vector2d, 4> quad;  // the corners on the plane, in order around the tile
      for (int corner = 0; corner < 4 && regular; ++corner) {
        const double x = (corner & 1) ? x1 : x0, y = (corner & 2) ? y1 : y0;
        const Eigen::Vector3d pixel(x, y, 1.0);
        const double s = map.denominator.dot(pixel);
        if (std::abs(s) <= 1e-6 * (map.k_inverse * pixel).norm() || s * s_sign < 0) {
          regular = false;
          break;
        }
        s_sign = s;
        const Eigen::Vector2d q = map.At(x, y);
        quad[corner == 2 ? 3 : corner == 3 ? 2 : corner] = q;
        const int t = Locate(q, hint);
        hint = t >= 0 ? t : hint;
        if (triangle != -2 && t != triangle) regular = false;
        triangle = t;
        if (regular && t < 0) {
          const int region = OutsideRegion(q);
          if (region == -1 || (corner > 0 && region != outside)) regular = false;
          outside = region;
        }
      }
      // On an outline that is not convex (a hand-held sweep's thin mesh) the corners' region
      // need not hold the whole tile: checked.
      std::vector<int> vertex_edges;
      if (regular && triangle < 0 && !OutsideRegionHolds(outside, quad, &vertex_edges)) regular = false;
      if (!regular && kind_ == Kind::kTriangles && std::min(x1 - x0, y1 - y0) + 1 > kMinTile) {
        // A triangle edge crosses it: the quarters that lie in one triangle take the fast path.
        const int xm = (x0 + x1) / 2, ym = (y0 + y1) / 2;
        fill(x0, y0, xm, ym);
        fill(xm + 1, y0, x1, ym);
        fill(x0, ym + 1, xm, y1);
        fill(xm + 1, ym + 1, x1, y1);
        return;
      }
      if (!regular) {
        for (int y = y0; y <= y1; ++y) {
          ViewSlots* row = slots->data() + static_cast<size_t>(y) * width;
          for (int x = x0; x <= x1; ++x) row[x] = WeightsAt(map.At(x, y), &hint);
        }
        return;
      }
      if (triangle < 0 && !vertex_edges.empty()) {
        // A vertex's region on an outline that is not convex: the edges from the vertex tie, and
        // pixel by pixel the nearer by rounding adds its far end at weight 0 and its witness; only
        // they are asked.
        for (int y = y0; y <= y1; ++y) {
          ViewSlots* row = slots->data() + static_cast<size_t>(y) * width;
          for (int x = x0; x <= x1; ++x) row[x] = OutsideWeights(map.At(x, y), &vertex_edges);
        }
        return;
      }
      if (triangle < 0) {
        fill_outside(outside, x0, y0, x1, y1);
        return;
      }
      // lambda_{1,2} = alpha + (r . pixel) / (s . pixel), lambda_0 = 1 - lambda_1 - lambda_2.
      const Barycentric& b = barycentric_[triangle];
      const Eigen::Vector2d alpha = b.inverse * (map.q_centre - b.p0);
      const Eigen::Matrix<double, 2, 3> r = -map.height * (b.inverse * map.numerator);
      const auto& tri = triangles_[triangle];
      const ViewSlots pattern = WithWitness(
          Merge({vertices_[tri[0]].view, vertices_[tri[1]].view, vertices_[tri[2]].view}, {1.0 / 3, 1.0 / 3, 1.0 / 3}),
          triangle_witness_[triangle]);
      std::array<int, 3> slot_of_vertex{};
      for (int k = 0; k < 3; ++k) {
        for (int j = 0; j < 3; ++j) {
          if (pattern.view[j] == vertices_[tri[k]].view) slot_of_vertex[k] = j;
        }
      }
      // The three linear forms of (x, y, 1), their y and constant terms hoisted per row.
      const double sx = map.denominator(0), s_y = map.denominator(1), s1 = map.denominator(2);
      const double ax = r(0, 0), a_y = r(0, 1), a1 = r(0, 2), bx = r(1, 0), b_y = r(1, 1), b1 = r(1, 2);
      for (int y = y0; y <= y1; ++y) {
        ViewSlots* row = slots->data() + static_cast<size_t>(y) * width;
        const double s_row = s_y * y + s1, a_row = a_y * y + a1, b_row = b_y * y + b1;
        for (int x = x0; x <= x1; ++x) {
          const double inv_s = 1.0 / (sx * x + s_row);
          const double l1 = std::max(0.0, alpha.x() + (ax * x + a_row) * inv_s);
          const double l2 = std::max(0.0, alpha.y() + (bx * x + b_row) * inv_s);
          const double l0 = std::max(0.0, 1.0 - l1 - l2);
          const double inv_sum = 1.0 / (l0 + l1 + l2);
          ViewSlots out;
          out.view = pattern.view;
          out.witness = pattern.witness;
          out.witness = pattern.witness;
          out.weight[slot_of_vertex[0]] += static_cast<float>(l0 * inv_sum);
          out.weight[slot_of_vertex[1]] += static_cast<float>(l1 * inv_sum);
          out.weight[slot_of_vertex[2]] += static_cast<float>(l2 * inv_sum);
          row[x] = out;
        }
      }
    };
    for (int ty = tile_rows.start; ty < tile_rows.end; ++ty) {
      const int y0 = ty * kTile, y1 = std::min(height, y0 + kTile) - 1;
      for (int tx = 0; tx < tiles_x; ++tx) fill(tx * kTile, y0, std::min(width, tx * kTile + kTile) - 1, y1);
      // Flattened while the band's rows are still in cache (a separate pass over a 1200x800
      // frame cost 1.6 ms more).
      ViewSlots* band = slots->data() + static_cast<size_t>(y0) * width;
      FlattenSlots(exponent, band, band + static_cast<size_t>(y1 + 1 - y0) * width);
    }
  });
}

namespace {

// The square-root flattening, one 4-lane step a slot: a slot is 16 bytes, its three view bytes
// (and a pad byte) in lane 0 and its weights in lanes 1 to 3, so lane 0 is masked out before the
// root (its bits may read as a denormal, which the root would take a slow path on) and kept as
// it was on the way back.
void FlattenBySquareRoot(ViewSlots* begin, ViewSlots* end) {
  static_assert(sizeof(ViewSlots) == 16 && offsetof(ViewSlots, weight) == 4, "one 4-lane register a slot");
  const cv::v_float32x4 weights = cv::v_reinterpret_as_f32(cv::v_uint32x4(0, ~0u, ~0u, ~0u));
  for (ViewSlots* s = begin; s != end; ++s) {
    float* lanes = reinterpret_cast<float*>(s);
    const cv::v_float32x4 slot = cv::v_load(lanes);
    const cv::v_float32x4 root = cv::v_sqrt(slot & weights);
    const float sum = cv::v_reduce_sum(root);
    const float inv_sum = sum > 0 ? 1.0f / sum : 0.0f;
    cv::v_store(lanes, cv::v_select(weights, root * cv::v_setall_f32(inv_sum), slot));
  }
}

}  // namespace

void FlattenSlots(double exponent, ViewSlots* begin, ViewSlots* end) {
  if (exponent == 1.0) return;
  if (exponent == 0.5) {  // the default: sqrt is exact and far cheaper than pow
    FlattenBySquareRoot(begin, end);
    return;
  }
  // Weights are never negative (ComputeWeights clamps them), so pow needs no test and a weight of
  // 0 stays 0.
  const float power = static_cast<float>(exponent);
  for (ViewSlots* s = begin; s != end; ++s) {
    const float a = std::pow(s->weight[0], power), b = std::pow(s->weight[1], power), c = std::pow(s->weight[2], power);
    const float sum = a + b + c;
    const float inv_sum = sum > 0 ? 1.0f / sum : 0.0f;
    s->weight = {a * inv_sum, b * inv_sum, c * inv_sum};
  }
}

void FlattenViewingWeights(double exponent, std::vector<ViewSlots>* slots) {
  if (exponent == 1.0 || slots->empty()) return;
  constexpr int kStripe = 8192;
  const int num_stripes = static_cast<int>((slots->size() + kStripe - 1) / kStripe);
  cv::parallel_for_(cv::Range(0, num_stripes), [&](const cv::Range& stripes) {
    ViewSlots* begin = slots->data() + static_cast<size_t>(stripes.start) * kStripe;
    ViewSlots* end = slots->data() + std::min(slots->size(), static_cast<size_t>(stripes.end) * kStripe);
    FlattenSlots(exponent, begin, end);
  });
}

}  // namespace px::render
