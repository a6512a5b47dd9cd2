#include "pipeline/render/gl/web_scene.h"

#include <bit>
#include <cstring>
#include <nlohmann/json.hpp>

#include "pipeline/render/gl/view_texels.h"

namespace px::render::gl {
namespace {

// The file is little-endian, written in the host's order.
static_assert(std::endian::native == std::endian::little, "web scenes are written on little-endian hosts only");

constexpr int kFloatsPerSegment = 8;

nlohmann::json Vector3(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

void Append(std::string* out, const void* data, size_t size) { out->append(static_cast<const char*>(data), size); }

}  // namespace

StatusOr<std::string> ExportWebScene(std::vector<PosedLayeredView> views, const GlSceneRendererOptions& options) {
  if (views.empty()) return InvalidArgumentError("web scene: no views");
  PX_ASSIGN_OR_RETURN(const PreparedScene scene, PrepareScene(&views, options.seam_skirts));
  const std::vector<ViewTexels>& texels = scene.texels;
  const GlViewMesh& mesh = scene.mesh;

  nlohmann::json header = {{"format", "parallax web scene"}, {"version", kWebSceneVersion}};
  nlohmann::json json_views = nlohmann::json::array();
  size_t offset = 0;  // from the end of the header; made absolute below
  for (size_t v = 0; v < views.size(); ++v) {
    const LayeredDepthView& view = views[v].depth;
    const Eigen::Matrix3d r = views[v].cam_from_world.RotationMatrix();
    nlohmann::json rotation = nlohmann::json::array();
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) rotation.push_back(r(i, j));
    }
    const size_t texel_bytes = static_cast<size_t>(view.camera.width) * view.camera.height * 16;
    const size_t segment_bytes = texels[v].kept_segments.size() * kFloatsPerSegment * sizeof(double);
    json_views.push_back({{"id", view.id.value},
                          {"width", view.camera.width},
                          {"height", view.camera.height},
                          {"fx", view.camera.fx},
                          {"fy", view.camera.fy},
                          {"cx", view.camera.cx},
                          {"cy", view.camera.cy},
                          {"rotation", rotation},  // cam_from_world, row-major
                          {"translation", Vector3(views[v].cam_from_world.translation)},
                          {"texels_offset", offset},
                          {"segments_offset", offset + texel_bytes},
                          {"segments", texels[v].kept_segments.size()}});
    offset += texel_bytes + segment_bytes;
  }
  nlohmann::json uniforms = nlohmann::json::array();
  for (const auto& u : MeshUniforms(mesh)) uniforms.push_back({u[0], u[1], u[2], u[3]});
  header["views"] = std::move(json_views);
  header["mesh"] = {{"origin", Vector3(mesh.origin)},
                    {"normal", Vector3(mesh.normal)},
                    {"axis1", Vector3(mesh.axis1)},
                    {"axis2", Vector3(mesh.axis2)},
                    {"uniforms", uniforms},
                    {"triangles", mesh.triangles.size()},
                    {"edges", mesh.outer_edges.size()},
                    {"single_view", mesh.single_view ? mesh.vertex_view[0] : -1}};
  header["rho_m"] = scene.rho_m;
  header["gamma_m"] = scene.rho_m * options.soft_z_gamma_fraction;
  header["viewing_weight_exponent"] = options.viewing_weight_exponent;
  header["texture_stretch"] = {{"fade_from", options.texture_stretch.fade_from},
                               {"fade_to", options.texture_stretch.fade_to}};
  header["warnings"] = scene.warnings;

  // Offsets made absolute: the prefix, then the header padded to a multiple of 8 (float64 blocks
  // must be aligned). The header's length depends on the offsets it holds: grown until it holds
  // its own.
  constexpr size_t kPrefixBytes = 16;
  const nlohmann::json relative = header["views"];
  std::string text = header.dump();
  size_t header_bytes = (text.size() + 7) / 8 * 8;
  while (true) {
    for (size_t v = 0; v < relative.size(); ++v) {
      for (const char* key : {"texels_offset", "segments_offset"}) {
        header["views"][v][key] = relative[v][key].get<size_t>() + kPrefixBytes + header_bytes;
      }
    }
    text = header.dump();
    if (text.size() <= header_bytes) break;
    header_bytes = (text.size() + 7) / 8 * 8;
  }
  text.resize(header_bytes, ' ');

  std::string out;
  out.reserve(kPrefixBytes + header_bytes + offset);
  const uint32_t prefix[4] = {0x53575850u /* "PXWS" */, kWebSceneVersion, static_cast<uint32_t>(header_bytes), 0};
  Append(&out, prefix, sizeof(prefix));
  out += text;
  for (size_t v = 0; v < views.size(); ++v) {
    const cv::Mat& t = texels[v].texels;
    for (int y = 0; y < t.rows; ++y) Append(&out, t.ptr(y), static_cast<size_t>(t.cols) * 16);
    for (int s : texels[v].kept_segments) {
      const DepthSegment& seg = views[v].depth.segments[s];
      const double values[kFloatsPerSegment] = {static_cast<double>(seg.bbox.x),
                                                static_cast<double>(seg.bbox.y),
                                                static_cast<double>(seg.bbox.width),
                                                static_cast<double>(seg.bbox.height),
                                                seg.inv_depth_a,
                                                seg.inv_depth_b,
                                                seg.inv_depth_c,
                                                static_cast<double>(s)};
      Append(&out, values, sizeof(values));
    }
  }
  return out;
}

}  // namespace px::render::gl
