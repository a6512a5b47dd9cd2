// The view mesh of paper section 6 (pipeline/render/ALGORITHM.md section 2), built on the CPU once
// per scene and handed to the GL weight pass as a texture: the plane fit to the views' centres of
// projection, the Delaunay triangulation of the centres in that plane (cv::Subdiv2D), and the
// boundary vertices duplicated radially outward at four times their distance from the centroid.
// The per-pixel viewing weights (ALGORITHM.md section 3) are computed from it in a shader.
//
// The plane, vertices and triangles are the CPU reference's ViewMesh (pipeline/render/view_mesh.h),
// as ALGORITHM.md 2 asks (a second triangulation broke the ties of a lattice and split the ring's
// quads on other diagonals: up to 45 % of a border view's summed weight moved to its neighbour);
// this adds what the weight shader needs and ViewMesh does not expose: the outer edges, and the
// 1D rig as a strip.
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

#include "pipeline/core/status.h"

namespace px::render::gl {

struct GlViewMesh {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();   // m: mean of the centres
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // n, towards the scene
  Eigen::Vector3d axis1 = Eigen::Vector3d::UnitX();   // e1, e2: in-plane axes
  Eigen::Vector3d axis2 = Eigen::Vector3d::UnitY();
  std::vector<Eigen::Vector2d> vertices;        // in-plane positions, duplicates appended
  std::vector<int> vertex_view;                 // the view (index into the inputs) of each vertex
  std::vector<std::array<int, 3>> triangles;    // the extended mesh
  std::vector<std::array<int, 2>> outer_edges;  // the extended mesh's outer boundary
  bool single_view = false;                     // one view (or all centres together): weight 1 everywhere
};

// `centres_in_world` and `optical_axes_in_world` (unit, R^T (0,0,1)) and `x_axes_in_world`, one of
// each per view. Collinear centres (a 1D rig) give a strip of triangles along the line whose
// weights go along it (BuildLineMesh in the .cc). INVALID_ARGUMENT for no views or mismatched lists.
StatusOr<GlViewMesh> BuildGlViewMesh(const std::vector<Eigen::Vector3d>& centres_in_world,
                                     const std::vector<Eigen::Vector3d>& optical_axes_in_world,
                                     const std::vector<Eigen::Vector3d>& x_axes_in_world);

// The CPU twin of the weight shader (ALGORITHM.md 3), without the weights: the point of the mesh
// plane a ray from `centre` along `dir` meets (behind the camera too), and the views with a slot
// there (-1 = none). The renderer samples it on a coarse grid to bound where each view is drawn.
Eigen::Vector2d MeshPointOfRay(const GlViewMesh& mesh, const Eigen::Vector3d& centre, const Eigen::Vector3d& dir);
std::array<int, 3> SlotViewsAt(const GlViewMesh& mesh, const Eigen::Vector2d& q);
// The first triangle of the mesh holding q (within 1e-6 in barycentric terms, as the shader
// tests), -1 if none: the shader tries the frame centre's first.
int TriangleAt(const GlViewMesh& mesh, const Eigen::Vector2d& q);

}  // namespace px::render::gl
