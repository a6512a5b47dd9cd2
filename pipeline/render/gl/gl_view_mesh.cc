#include "pipeline/render/gl/gl_view_mesh.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <string>

#include "pipeline/render/view_mesh.h"

namespace px::render::gl {

namespace {

// A 1D (collinear) rig, as the CPU reference's ViewMesh does it (ALGORITHM.md 2): the plane holds
// the line and is as square to the views as it can be, and the weights go along the line only.
// Drawn for the same weight shader as a strip of triangles: each view's vertex on the line and
// two copies of it at +-L across it, so that in every triangle of the strip the barycentric
// weight of view b is the ray point's fraction of the way from view a to b along the line
// (whatever its distance across); beyond the strip the nearest outer edge gives the same, and
// beyond the ends the end view has weight 1.
StatusOr<GlViewMesh> BuildLineMesh(const std::vector<Eigen::Vector3d>& centres,
                                   const Eigen::Vector3d& mean_axis,
                                   const Eigen::Vector3d& mean_x,
                                   Eigen::Vector3d line,
                                   GlViewMesh* mesh) {
  const int n = static_cast<int>(centres.size());
  if (line.dot(mean_x) < 0) line = -line;
  Eigen::Vector3d normal = mean_axis - mean_axis.dot(line) * line;
  if (normal.norm() < 1e-9) normal = line.unitOrthogonal();
  mesh->normal = normal.normalized();
  mesh->axis1 = line.normalized();
  mesh->axis2 = mesh->normal.cross(mesh->axis1);
  std::vector<std::pair<double, int>> along;  // u, view
  for (int i = 0; i < n; ++i) along.emplace_back((centres[i] - mesh->origin).dot(mesh->axis1), i);
  std::sort(along.begin(), along.end());
  const double half_width = 4.0 * std::max(along.back().first - along.front().first, 1e-3);
  mesh->vertices.clear();
  mesh->vertex_view.clear();
  for (const auto& [u, view] : along) {  // per view: on the line, above, below
    for (double v : {0.0, half_width, -half_width}) {
      mesh->vertices.emplace_back(u, v);
      mesh->vertex_view.push_back(view);
    }
  }
  for (int i = 0; i + 1 < n; ++i) {
    const int a = 3 * i, b = 3 * (i + 1);
    if (along[i + 1].first - along[i].first < 1e-9) continue;  // two views at one place: no span between
    for (int side : {1, 2}) {                                  // above, below
      mesh->triangles.push_back({a, b, b + side});
      mesh->triangles.push_back({a, b + side, a + side});
      mesh->outer_edges.push_back({a + side, b + side});
    }
  }
  const int last = 3 * (n - 1);
  for (int end : {0, last}) {
    mesh->outer_edges.push_back({end + 1, end});
    mesh->outer_edges.push_back({end, end + 2});
  }
  // Unreachable from BuildGlViewMesh (coincident centres take the single-view path); kept so that a
  // degenerate line can never yield an empty mesh.
  if (mesh->triangles.empty()) {
    return FailedPreconditionError("view mesh: the " + std::to_string(n) + " collinear centres span no length");
  }
  return *mesh;
}

}  // namespace

StatusOr<GlViewMesh> BuildGlViewMesh(const std::vector<Eigen::Vector3d>& centres_in_world,
                                     const std::vector<Eigen::Vector3d>& optical_axes_in_world,
                                     const std::vector<Eigen::Vector3d>& x_axes_in_world) {
  const int n = static_cast<int>(centres_in_world.size());
  if (n == 0) return InvalidArgumentError("view mesh: no views");
  if (optical_axes_in_world.size() != centres_in_world.size() || x_axes_in_world.size() != centres_in_world.size()) {
    return InvalidArgumentError("view mesh: " + std::to_string(n) + " centres but " +
                                std::to_string(optical_axes_in_world.size()) + " optical axes and " +
                                std::to_string(x_axes_in_world.size()) + " x axes");
  }
  GlViewMesh mesh;
  Eigen::Vector3d mean_axis = Eigen::Vector3d::Zero();
  Eigen::Vector3d mean_x = Eigen::Vector3d::Zero();
  for (int i = 0; i < n; ++i) {
    mesh.origin += centres_in_world[i] / n;
    mean_axis += optical_axes_in_world[i] / n;
    mean_x += x_axes_in_world[i] / n;
  }
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  double spread = 0;
  for (const Eigen::Vector3d& c : centres_in_world) {
    scatter += (c - mesh.origin) * (c - mesh.origin).transpose();
    spread = std::max(spread, (c - mesh.origin).norm());
  }
  mesh.vertex_view.push_back(0);
  mesh.vertices.push_back(Eigen::Vector2d::Zero());
  if (n == 1 || spread < 1e-9) {
    mesh.single_view = true;
    return mesh;
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(scatter);  // ascending eigenvalues
  if (eigen.eigenvalues()(1) < 1e-6 * eigen.eigenvalues()(2))
    return BuildLineMesh(centres_in_world, mean_axis, mean_x, eigen.eigenvectors().col(2), &mesh);
  // The plane, the Delaunay triangles and the extension ring are the CPU reference's (ALGORITHM.md
  // 2: Subdiv2D breaks the ties of a regular lattice by its input, so the GL back end must not
  // triangulate again; the ring's quads are split on the same diagonal).
  std::vector<Eigen::Matrix3d> world_from_cam(n);
  for (int i = 0; i < n; ++i) {
    world_from_cam[i].col(0) = x_axes_in_world[i];
    world_from_cam[i].col(1) = optical_axes_in_world[i].cross(x_axes_in_world[i]);
    world_from_cam[i].col(2) = optical_axes_in_world[i];
  }
  PX_ASSIGN_OR_RETURN(ViewMesh reference, ViewMesh::Build(centres_in_world, world_from_cam));
  if (reference.kind() != ViewMesh::Kind::kTriangles) {
    return InternalError("view mesh: the CPU reference did not triangulate " + std::to_string(n) + " centres");
  }
  mesh.origin = reference.origin();
  mesh.normal = reference.normal();
  mesh.axis1 = reference.axis_u();
  mesh.axis2 = reference.axis_v();
  mesh.vertices.clear();
  mesh.vertex_view.clear();
  for (const ViewMesh::Vertex& vertex : reference.vertices()) {
    mesh.vertices.push_back(vertex.position);
    mesh.vertex_view.push_back(vertex.view);
  }
  mesh.triangles = reference.triangles();
  // Each ring quad is two triangles; the one with two duplicated vertices holds the outer edge.
  for (size_t t = reference.NumDelaunayTriangles(); t < mesh.triangles.size(); ++t) {
    std::array<int, 2> edge{};
    int duplicates = 0;
    for (int vertex : mesh.triangles[t]) {
      if (vertex >= n && duplicates < 2) edge[duplicates++] = vertex;
    }
    if (duplicates == 2) mesh.outer_edges.push_back(edge);
  }
  return mesh;
}

Eigen::Vector2d MeshPointOfRay(const GlViewMesh& mesh, const Eigen::Vector3d& centre, const Eigen::Vector3d& dir) {
  const double s = mesh.normal.dot(dir);
  const double h = mesh.normal.dot(centre - mesh.origin);
  const Eigen::Vector3d x = std::abs(s) <= 1e-9 * dir.norm() ? centre : Eigen::Vector3d(centre - (h / s) * dir);
  return Eigen::Vector2d((x - mesh.origin).dot(mesh.axis1), (x - mesh.origin).dot(mesh.axis2));
}

int TriangleAt(const GlViewMesh& mesh, const Eigen::Vector2d& q) {
  for (size_t i = 0; i < mesh.triangles.size(); ++i) {
    const auto& t = mesh.triangles[i];
    const Eigen::Vector2d a = mesh.vertices[t[0]], v0 = mesh.vertices[t[1]] - a, v1 = mesh.vertices[t[2]] - a,
                          v2 = q - a;
    const double den = v0.x() * v1.y() - v1.x() * v0.y();
    if (std::abs(den) < 1e-20) continue;
    const double wb = (v2.x() * v1.y() - v1.x() * v2.y()) / den, wc = (v0.x() * v2.y() - v2.x() * v0.y()) / den;
    if (1 - wb - wc >= -1e-6 && wb >= -1e-6 && wc >= -1e-6) return static_cast<int>(i);
  }
  return -1;
}

std::array<int, 3> SlotViewsAt(const GlViewMesh& mesh, const Eigen::Vector2d& q) {
  std::array<int, 3> views = {-1, -1, -1};
  auto add = [&](int view) {
    for (int& slot : views) {
      if (slot == view) return;
      if (slot < 0) {
        slot = view;
        return;
      }
    }
  };
  if (mesh.single_view) {
    views[0] = mesh.vertex_view[0];
    return views;
  }
  if (const int t = TriangleAt(mesh, q); t >= 0) {
    for (int k = 0; k < 3; ++k) add(mesh.vertex_view[mesh.triangles[t][k]]);
    return views;
  }
  double best = 1e300;
  std::array<int, 2> best_edge = {0, 0};
  for (const auto& e : mesh.outer_edges) {
    const Eigen::Vector2d a = mesh.vertices[e[0]], ab = mesh.vertices[e[1]] - a;
    const double t = std::clamp((q - a).dot(ab) / std::max(ab.squaredNorm(), 1e-30), 0.0, 1.0);
    const double dist = (q - (a + t * ab)).norm();
    if (dist < best) best = dist, best_edge = e;
  }
  add(mesh.vertex_view[best_edge[0]]);
  add(mesh.vertex_view[best_edge[1]]);
  return views;
}

}  // namespace px::render::gl
