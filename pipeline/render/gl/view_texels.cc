#include "pipeline/render/gl/view_texels.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "pipeline/render/bilinear_prefilter.h"
#include "pipeline/render/seam_skirts.h"

namespace px::render::gl {
namespace {

// A segment whose plane is finite with positive inverse depth at the four corners of its
// rectangle (the bbox grown by one pixel).
bool SegmentUsable(const DepthSegment& s) {
  if (!std::isfinite(s.inv_depth_a) || !std::isfinite(s.inv_depth_b) || !std::isfinite(s.inv_depth_c)) return false;
  const double x0 = s.bbox.x - 1, x1 = s.bbox.x + s.bbox.width, y0 = s.bbox.y - 1, y1 = s.bbox.y + s.bbox.height;
  for (double x : {x0, x1}) {
    for (double y : {y0, y1}) {
      if (s.InverseDepthAt(x, y) <= 0) return false;
    }
  }
  return true;
}

// INVALID_ARGUMENT, naming the view, unless both layers' colour, weight and segment images are
// CV_8UC3, CV_32F and CV_32S of the camera's size.
Status CheckLayerImages(const LayeredDepthView& view, const std::string& view_name) {
  const int w = view.camera.width, h = view.camera.height;
  for (int l = 0; l < 2; ++l) {
    const SegmentLayer& layer = view.layers[l];
    if (layer.colour.type() != CV_8UC3 || layer.weight.type() != CV_32F || layer.segment.type() != CV_32S ||
        layer.colour.size() != cv::Size(w, h) || layer.weight.size() != cv::Size(w, h) ||
        layer.segment.size() != cv::Size(w, h)) {
      return InvalidArgumentError("gl renderer: " + view_name + " layer " + std::to_string(l) +
                                  ": colour, weight and segment must be CV_8UC3, CV_32F and CV_32S of the camera's "
                                  "size " +
                                  std::to_string(w) + "x" + std::to_string(h));
    }
  }
  return OkStatus();
}

// The view's texels, its colours prefiltered for the bilinear sample (as the CPU reference's).
ViewTexels MakeViewTexels(const LayeredDepthView& view) {
  ViewTexels out;
  const int w = view.camera.width, h = view.camera.height;
  const std::array<cv::Mat, 2> colours = PrefilterForBilinear(view);  // as the CPU reference's texels
  std::vector<bool> usable(view.segments.size());
  for (size_t s = 0; s < view.segments.size(); ++s) {
    if (view.segments[s].bbox.empty()) continue;  // covers no pixel: nothing to draw, nothing wrong
    usable[s] = SegmentUsable(view.segments[s]);
    if (usable[s])
      out.kept_segments.push_back(static_cast<int>(s));
    else
      ++out.dropped_segments;
  }
  out.texels.create(h, w, CV_32SC4);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      cv::Vec4i& texel = out.texels.at<cv::Vec4i>(y, x);
      texel = cv::Vec4i(0, 0, -1, -1);
      for (int l = 0; l < 2; ++l) {
        const float weight = view.layers[l].weight.at<float>(y, x);
        const int segment = view.layers[l].segment.at<int32_t>(y, x);
        const cv::Vec3b c = colours[l].at<cv::Vec3b>(y, x);
        const bool segment_ok = segment >= 0 && segment < view.NumSegments() && usable[segment];
        const bool weight_ok = std::isfinite(weight) && weight >= 0 && weight <= 1;
        float kept = 0;
        if (segment_ok && weight_ok && weight > 0) {
          kept = weight;
          texel[2 + l] = segment;
          ++out.kept_texels;
        } else if (!(weight == 0)) {  // NaN, out of range, or weight on a bad segment
          ++out.dropped_texels;
        }
        const uint32_t a = cv::saturate_cast<uint8_t>(std::lround(kept * 255.0f));
        texel[l] = static_cast<int32_t>(c[0] | (uint32_t{c[1]} << 8) | (uint32_t{c[2]} << 16) | (a << 24));
      }
    }
  }
  return out;
}

// The warnings MakeViewTexels' counts call for, each naming the view.
std::vector<std::string> ViewTexelWarnings(const ViewTexels& texels, int num_segments, const std::string& view_name) {
  std::vector<std::string> warnings;
  if (texels.dropped_segments > 0) {
    warnings.push_back(view_name + ": " + std::to_string(texels.dropped_segments) + " of " +
                       std::to_string(num_segments) +
                       " segments dropped (plane not finite or depth not positive over its rectangle)");
  }
  if (texels.dropped_texels > 0) {
    warnings.push_back(view_name + ": " + std::to_string(texels.dropped_texels) +
                       " texels dropped (weight not finite or outside [0, 1], or its segment invalid or dropped)");
  }
  if (texels.kept_texels == 0) {
    warnings.push_back(view_name + ": no texel with depth (no usable segment or weight); the view is left out");
  }
  return warnings;
}

// The view mesh over the views `drawn` (indices into `cam_from_world`); its vertex views index
// `cam_from_world`.
StatusOr<GlViewMesh> MeshOfDrawnViews(const std::vector<Rigid3>& cam_from_world, const std::vector<int>& drawn) {
  if (drawn.empty()) return FailedPreconditionError("gl renderer: no view has a usable segment (no valid depth)");
  std::vector<Eigen::Vector3d> centres, axes, x_axes;
  for (int v : drawn) {
    const Eigen::Matrix3d world_from_cam = cam_from_world[v].RotationMatrix().transpose();
    centres.push_back(CameraCentre(cam_from_world[v]));
    axes.push_back(world_from_cam.col(2));
    x_axes.push_back(world_from_cam.col(0));
  }
  PX_ASSIGN_OR_RETURN(GlViewMesh mesh, BuildGlViewMesh(centres, axes, x_axes));
  for (int& view : mesh.vertex_view) view = drawn[view];
  if (mesh.single_view) mesh.vertex_view[0] = drawn[0];
  return mesh;
}

// PreparedScene::rho_m and median_depth_m.
void SceneDepthRange(const std::vector<PosedLayeredView>& views, double* rho, double* median) {
  std::vector<float> depths;
  for (const PosedLayeredView& view : views) {
    const LayeredDepthView& d = view.depth;
    if (d.depth_m.type() != CV_32F || d.layers[0].weight.type() != CV_32F ||
        d.depth_m.size() != d.layers[0].weight.size()) {
      continue;
    }
    for (int y = 0; y < d.depth_m.rows; ++y) {
      const float* z = d.depth_m.ptr<float>(y);
      const float* w = d.layers[0].weight.ptr<float>(y);
      for (int x = 0; x < d.depth_m.cols; ++x) {
        if (w[x] > 0 && std::isfinite(z[x]) && z[x] > 0) depths.push_back(z[x]);
      }
    }
  }
  if (depths.empty()) {
    *rho = 1.0, *median = 1.0;
    return;
  }
  auto at = [&](double q) {
    auto it = depths.begin() + static_cast<std::ptrdiff_t>(q * (depths.size() - 1));
    std::nth_element(depths.begin(), it, depths.end());
    return static_cast<double>(*it);
  };
  const double z1 = at(0.01), z50 = at(0.5), z99 = at(0.99);
  *median = z50;
  *rho = std::max(z99 - z1, 0.01 * z50);
}

}  // namespace

std::string ViewName(const LayeredDepthView& view, int index) {
  return "view " + std::to_string(index) + " (id " + std::to_string(view.id.value) + ")";
}

StatusOr<PreparedScene> PrepareScene(std::vector<PosedLayeredView>* views, const SeamSkirtOptions& skirts) {
  PreparedScene scene;
  std::vector<int> drawn;
  std::vector<Rigid3> poses;
  for (int v = 0; v < static_cast<int>(views->size()); ++v) {
    LayeredDepthView& view = (*views)[v].depth;
    view = WithSeamSkirts(view, skirts);
    const std::string name = ViewName(view, v);
    PX_RETURN_IF_ERROR(CheckLayerImages(view, name));
    ViewTexels texels = MakeViewTexels(view);
    for (std::string& warning : ViewTexelWarnings(texels, view.NumSegments(), name)) {
      scene.warnings.push_back(std::move(warning));
    }
    if (texels.kept_texels == 0) texels.kept_segments.clear();
    if (!texels.kept_segments.empty()) drawn.push_back(v);
    poses.push_back((*views)[v].cam_from_world);
    scene.texels.push_back(std::move(texels));
  }
  PX_ASSIGN_OR_RETURN(scene.mesh, MeshOfDrawnViews(poses, drawn));
  SceneDepthRange(*views, &scene.rho_m, &scene.median_depth_m);
  return scene;
}

std::vector<std::array<float, 4>> MeshUniforms(const GlViewMesh& mesh) {
  auto corner = [&](int vertex) {
    const Eigen::Vector2d& p = mesh.vertices[vertex];
    return std::array<float, 4>{
        static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(mesh.vertex_view[vertex]), 0.0f};
  };
  std::vector<std::array<float, 4>> uniforms;
  for (const auto& triangle : mesh.triangles) {
    for (int vertex : triangle) uniforms.push_back(corner(vertex));
  }
  for (const auto& edge : mesh.outer_edges) {
    for (int vertex : edge) uniforms.push_back(corner(vertex));
  }
  if (uniforms.empty()) uniforms.push_back({0, 0, 0, 0});
  return uniforms;
}

}  // namespace px::render::gl
