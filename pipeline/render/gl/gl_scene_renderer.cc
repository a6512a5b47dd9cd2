#include "pipeline/render/gl/gl_scene_renderer.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <ctime>
#include <opencv2/core.hpp>

#include "pipeline/core/log.h"
#include "pipeline/render/border_holes.h"
#include "pipeline/render/color_effects.h"
#include "pipeline/render/depth_of_field.h"
#include "pipeline/render/gl/gl_program.h"
#include "pipeline/render/gl/gl_render_shaders.h"
#include "pipeline/render/gl/view_texels.h"
#include "pipeline/render/hole_fill.h"
#include "pipeline/render/hole_views.h"
#include "pipeline/render/layered_scene.h"

namespace px::render::gl {
namespace {

constexpr int kFloatsPerInstance = 22;  // corners 8, homography 9, plane 3, segment 1, texture weight 1
constexpr double kNearDepthM = 1e-3;

// The segment vertex shader's per-instance attributes in the bound buffer, from instance `first`
// on (one buffer holds every view's instances; each view's draw starts at its own).
void PointInstanceAttributes(const GlFunctions& gl, size_t first) {
  const GLsizei stride = kFloatsPerInstance * sizeof(float);
  const std::array<std::pair<int, int>, 7> attributes = {{{4, 0}, {4, 4}, {3, 8}, {3, 11}, {3, 14}, {3, 17}, {2, 20}}};
  for (int a = 0; a < static_cast<int>(attributes.size()); ++a) {
    gl.EnableVertexAttribArray(a);
    const size_t offset = (first * kFloatsPerInstance + attributes[a].second) * sizeof(float);
    gl.VertexAttribPointer(a, attributes[a].first, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<const void*>(offset));
    gl.VertexAttribDivisor(a, 1);
  }
}

// Process CPU time between marks, after a glFinish where GL work is pending; inert when off.
class PassClock {
 public:
  PassClock(const GlFunctions& gl, bool on) : gl_(gl), on_(on), last_(on ? Now() : 0) {}
  void Mark(double* ms, bool finish_gl) {
    if (!on_) return;
    if (finish_gl) gl_.Finish();
    const double now = Now();
    *ms = 1e3 * (now - last_);
    last_ = now;
  }

 private:
  static double Now() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
  }
  const GlFunctions& gl_;
  bool on_;
  double last_;
};

Eigen::Matrix3f ToFloat(const Eigen::Matrix3d& m) { return m.cast<float>(); }

void SetUniformMatrix3(const GlFunctions& gl, GLuint program, const char* name, const Eigen::Matrix3d& m) {
  const Eigen::Matrix3f f = ToFloat(m);  // column-major, as GL wants with transpose = false
  gl.UniformMatrix3fv(gl.GetUniformLocation(program, name), 1, GL_FALSE, f.data());
}
void SetUniform3(const GlFunctions& gl, GLuint program, const char* name, const Eigen::Vector3d& v) {
  gl.Uniform3f(gl.GetUniformLocation(program, name),
               static_cast<float>(v.x()),
               static_cast<float>(v.y()),
               static_cast<float>(v.z()));
}
void BindTextureUnit(const GlFunctions& gl, GLuint program, const char* name, int unit, GLuint texture) {
  gl.ActiveTexture(GL_TEXTURE0 + unit);
  gl.BindTexture(GL_TEXTURE_2D, texture);
  gl.Uniform1i(gl.GetUniformLocation(program, name), unit);
}

StatusOr<GlObject> UploadTexture(const GlFunctions& gl,
                                 GLenum internal_format,
                                 GLenum format,
                                 GLenum type,
                                 const cv::Mat& image,
                                 const std::string& what) {
  PX_ASSIGN_OR_RETURN(GlObject texture, MakeTexture2D(gl, internal_format, image.cols, image.rows, what));
  const cv::Mat contiguous = image.isContinuous() ? image : image.clone();
  gl.BindTexture(GL_TEXTURE_2D, texture.id());
  gl.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
  gl.TexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, image.cols, image.rows, format, type, contiguous.data);
  gl.BindTexture(GL_TEXTURE_2D, 0);
  const std::string errors = DrainGlErrors(gl);
  if (!errors.empty()) return InternalError(what + ": uploading raised " + errors);
  return texture;
}

}  // namespace

Status GlSceneRendererOptions::Validate() const {
  if (!(viewing_weight_exponent > 0 && viewing_weight_exponent <= 1)) {
    return InvalidArgumentError("gl renderer: viewing_weight_exponent " + std::to_string(viewing_weight_exponent) +
                                " is outside (0, 1]");
  }
  // The CPU reference's checks of the same fields, so both back ends refuse the same values.
  RenderOptions render;
  render.soft_z_gamma_fraction = soft_z_gamma_fraction;
  render.hole_window_radius_px = hole_window_radius_px;
  render.border_holes = border_holes;
  render.texture_stretch = texture_stretch;
  const Status render_status = render.Validate();
  if (!render_status.ok()) return InvalidArgumentError("gl renderer: " + render_status.message());
  return context.Validate();
}

GlSceneRendererOptions GlOptionsFrom(const RenderOptions& render) {
  GlSceneRendererOptions options;
  options.viewing_weight_exponent = render.viewing_weight_exponent;
  options.holes_from_other_views = render.holes_from_other_views;
  options.border_holes = render.border_holes;
  options.seam_skirts = render.seam_skirts;
  options.texture_stretch = render.texture_stretch;
  options.soft_z_gamma_fraction = render.soft_z_gamma_fraction;
  options.hole_window_radius_px = render.hole_window_radius_px;
  return options;
}

StatusOr<std::unique_ptr<GlSceneRenderer>> GlSceneRenderer::Create(std::vector<PosedLayeredView> views,
                                                                   const GlSceneRendererOptions& options) {
  PX_RETURN_IF_ERROR(options.Validate());
  if (views.empty()) return InvalidArgumentError("gl renderer: no views");
  PX_ASSIGN_OR_RETURN(std::unique_ptr<GlContext> context, CreateGlContext(options.context));
  return Create(std::move(views), std::move(context), options);
}

StatusOr<std::unique_ptr<GlSceneRenderer>> GlSceneRenderer::Create(std::vector<PosedLayeredView> views,
                                                                   std::unique_ptr<GlContext> context,
                                                                   const GlSceneRendererOptions& options) {
  if (views.empty()) return InvalidArgumentError("gl renderer: no views");
  if (!context) return InvalidArgumentError("gl renderer: no GL context");
  GlSceneRendererOptions checked = options;
  checked.context = GlContextOptions{};  // the context is made already
  PX_RETURN_IF_ERROR(checked.Validate());
  std::unique_ptr<GlSceneRenderer> renderer(new GlSceneRenderer());
  renderer->viewing_weight_exponent_ = options.viewing_weight_exponent;
  renderer->soft_z_gamma_fraction_ = options.soft_z_gamma_fraction;
  renderer->hole_window_radius_px_ = options.hole_window_radius_px;
  renderer->holes_from_other_views_ = options.holes_from_other_views;
  renderer->border_holes_ = options.border_holes;
  renderer->seam_skirts_ = options.seam_skirts;
  renderer->texture_stretch_ = options.texture_stretch;
  renderer->context_ = std::move(context);
  renderer->views_ = std::move(views);
  ScopedCurrent current(renderer->context_.get());
  PX_RETURN_IF_ERROR(current.status());
  PX_RETURN_IF_ERROR(renderer->Upload());
  Logger("render")->info("gl renderer on {}: {} views, {} mesh triangles, rho {:.3f} m{}",
                         renderer->context_->info().ToString(),
                         renderer->views_.size(),
                         renderer->mesh_.triangles.size(),
                         renderer->rho_m_,
                         renderer->warnings_.empty() ? "" : ", with warnings");
  for (const std::string& warning : renderer->warnings_) Logger("render")->warn("gl renderer: {}", warning);
  return renderer;
}

GlSceneRenderer::~GlSceneRenderer() {
  if (!context_) return;
  // GL objects are deleted while their context is current.
  ScopedCurrent current(context_.get());
  textures_.clear();
  targets_.clear();
  weights_program_.Reset();
  segment_program_.Reset();
  segment_floor_program_.Reset();
  resolve_program_.Reset();
  empty_vertex_array_.Reset();
  instance_vertex_array_.Reset();
  instance_buffer_.Reset();
}

Status GlSceneRenderer::Upload() {
  const GlFunctions& gl = context_->gl();
  const int max_size = context_->info().max_texture_size;
  PX_ASSIGN_OR_RETURN(PreparedScene scene, PrepareScene(&views_, seam_skirts_));
  for (std::string& warning : scene.warnings) warnings_.push_back(std::move(warning));
  for (int v = 0; v < static_cast<int>(views_.size()); ++v) {
    const std::string name = ViewName(views_[v].depth, v);
    const int w = views_[v].depth.camera.width, h = views_[v].depth.camera.height;
    if (w > max_size || h > max_size) {
      return InvalidArgumentError("gl renderer: " + name + " is " + std::to_string(w) + "x" + std::to_string(h) +
                                  ", larger than the GL context's GL_MAX_TEXTURE_SIZE " + std::to_string(max_size));
    }
    ViewTextures textures;
    textures.kept_segments = std::move(scene.texels[v].kept_segments);
    PX_ASSIGN_OR_RETURN(
        textures.texels,
        UploadTexture(
            gl, GL_RGBA32UI, GL_RGBA_INTEGER, GL_UNSIGNED_INT, scene.texels[v].texels, name + " segment texels"));
    textures_.push_back(std::move(textures));
  }
  mesh_ = std::move(scene.mesh);
  rho_m_ = scene.rho_m;
  median_depth_m_ = scene.median_depth_m;
  // The mesh as a uniform array (x, y, view, 0): the triangles' corners, then the outer edges'
  // ends. A loop over uniforms costs llvmpipe far less than one over texel fetches.
  mesh_uniforms_ = MeshUniforms(mesh_);
  GLint max_vectors = 0;
  gl.GetIntegerv(GL_MAX_FRAGMENT_UNIFORM_VECTORS, &max_vectors);
  constexpr int kOtherUniformVectors = 16;  // the weight shader's matrix, vectors and counts
  if (static_cast<int>(mesh_uniforms_.size()) + kOtherUniformVectors > max_vectors) {
    return FailedPreconditionError("gl renderer: the view mesh of " + std::to_string(mesh_.triangles.size()) +
                                   " triangles needs " + std::to_string(mesh_uniforms_.size()) +
                                   " uniform vectors, more than the context's GL_MAX_FRAGMENT_UNIFORM_VECTORS " +
                                   std::to_string(max_vectors) + " allows");
  }

  const std::string weights_shader =
      "#define MESH_VECTORS " + std::to_string(mesh_uniforms_.size()) + "\n" + std::string(kViewWeightsFragmentShader);
  PX_ASSIGN_OR_RETURN(weights_program_, BuildProgram(gl, "view_weights", kFullScreenVertexShader, weights_shader));
  PX_ASSIGN_OR_RETURN(segment_program_, BuildProgram(gl, "segments", kSegmentVertexShader, kSegmentFragmentShader));
  PX_ASSIGN_OR_RETURN(resolve_program_,
                      BuildProgram(gl, "soft_z_resolve", kFullScreenVertexShader, kSoftZResolveFragmentShader));
  empty_vertex_array_ = GlObject(&gl, GlObjectKind::kVertexArray);
  instance_vertex_array_ = GlObject(&gl, GlObjectKind::kVertexArray);
  instance_buffer_ = GlObject(&gl, GlObjectKind::kBuffer);
  gl.BindVertexArray(instance_vertex_array_.id());
  gl.BindBuffer(GL_ARRAY_BUFFER, instance_buffer_.id());
  PointInstanceAttributes(gl, 0);
  gl.BindVertexArray(0);
  const std::string errors = DrainGlErrors(gl);
  if (!errors.empty()) return InternalError("gl renderer: setting up raised " + errors);
  return OkStatus();
}

StatusOr<GlSceneRenderer::Targets*> GlSceneRenderer::TargetsFor(int width, int height) {
  auto it = targets_.find({width, height});
  if (it != targets_.end()) return &it->second;
  const GlFunctions& gl = context_->gl();
  Targets t;
  const std::string size = std::to_string(width) + "x" + std::to_string(height);
  PX_ASSIGN_OR_RETURN(t.slot_views, MakeTexture2D(gl, GL_RGBA32F, width, height, "slot views " + size));
  PX_ASSIGN_OR_RETURN(t.slot_weights, MakeTexture2D(gl, GL_RGBA32F, width, height, "slot weights " + size));
  PX_ASSIGN_OR_RETURN(t.weights_fbo, MakeFramebuffer(gl, {t.slot_views.id(), t.slot_weights.id()}, "weights " + size));
  for (int k = 0; k < 3; ++k) {
    PX_ASSIGN_OR_RETURN(t.colour[k], MakeTexture2D(gl, GL_RGBA16, width, height, "rendering buffer " + size));
    PX_ASSIGN_OR_RETURN(t.depth[k], MakeTexture2D(gl, GL_RGBA16, width, height, "rendering buffer depth " + size));
  }
  for (int k = 0; k < 3; ++k) {
    PX_ASSIGN_OR_RETURN(
        t.slot_fbo[k],
        MakeFramebuffer(gl, {t.colour[k].id(), t.depth[k].id()}, "rendering buffer " + std::to_string(k) + " " + size));
  }
  PX_ASSIGN_OR_RETURN(t.resolved_colour, MakeTexture2D(gl, GL_RGBA32F, width, height, "resolved colour " + size));
  PX_ASSIGN_OR_RETURN(t.resolved_depth, MakeTexture2D(gl, GL_R32F, width, height, "resolved depth " + size));
  PX_ASSIGN_OR_RETURN(t.resolve_fbo,
                      MakeFramebuffer(gl, {t.resolved_colour.id(), t.resolved_depth.id()}, "resolve " + size));
  return &targets_.emplace(std::make_pair(width, height), std::move(t)).first->second;
}

StatusOr<GlSceneRenderer::RawFrame> GlSceneRenderer::RenderRaw(const CameraModel& camera,
                                                               const Rigid3& cam_from_world,
                                                               bool with_slots,
                                                               double weight_exponent) {
  const GlFunctions& gl = context_->gl();
  const int width = camera.width, height = camera.height;
  PX_ASSIGN_OR_RETURN(Targets * t, TargetsFor(width, height));
  stats_ = GlFrameStats{};
  PassClock clock(gl, time_passes_);
  const Eigen::Matrix3d k_novel = camera.K();
  const Eigen::Matrix3d rotation = cam_from_world.RotationMatrix();
  const Eigen::Vector3d centre = CameraCentre(cam_from_world);

  // Pass 1: viewing weights.
  gl.Disable(GL_BLEND);
  gl.Viewport(0, 0, width, height);
  gl.BindFramebuffer(GL_FRAMEBUFFER, t->weights_fbo.id());
  gl.UseProgram(weights_program_.id());
  GLuint p = weights_program_.id();
  SetUniformMatrix3(gl, p, "dir_from_pixel", rotation.transpose() * k_novel.inverse());
  SetUniform3(gl, p, "centre", centre);
  SetUniform3(gl, p, "mesh_origin", mesh_.origin);
  SetUniform3(gl, p, "mesh_normal", mesh_.normal);
  SetUniform3(gl, p, "mesh_axis1", mesh_.axis1);
  SetUniform3(gl, p, "mesh_axis2", mesh_.axis2);
  gl.Uniform4fv(
      gl.GetUniformLocation(p, "mesh"), static_cast<GLsizei>(mesh_uniforms_.size()), mesh_uniforms_.front().data());
  gl.Uniform1i(gl.GetUniformLocation(p, "num_triangles"), static_cast<int>(mesh_.triangles.size()));
  gl.Uniform1i(gl.GetUniformLocation(p, "num_edges"), static_cast<int>(mesh_.outer_edges.size()));
  gl.Uniform1i(gl.GetUniformLocation(p, "single_view"), mesh_.single_view ? mesh_.vertex_view[0] : -1);
  gl.Uniform1f(gl.GetUniformLocation(p, "weight_exponent"), static_cast<float>(weight_exponent));
  const Eigen::Vector3d frame_centre(camera.width / 2.0, camera.height / 2.0, 1.0);
  gl.Uniform1i(
      gl.GetUniformLocation(p, "hint_triangle"),
      mesh_.single_view
          ? -1
          : TriangleAt(mesh_, MeshPointOfRay(mesh_, centre, rotation.transpose() * k_novel.inverse() * frame_centre)));
  gl.BindVertexArray(empty_vertex_array_.id());
  gl.DrawArrays(GL_TRIANGLES, 0, 3);

  // Where each view holds a slot, from the CPU twin of the weight shader on a coarse grid (each
  // box grown by one cell): views drawn nowhere are skipped and the rest scissored to their box,
  // so a frame shades about three views' worth of fragments per pixel, not all of them.
  clock.Mark(&stats_.weights_ms, /*finish_gl=*/true);
  const std::vector<SlotBoxes> view_boxes = ViewBoxes(camera, cam_from_world);

  // Pass 2: every view's segments, front to back, into the three rendering buffers.
  std::vector<std::vector<float>> instances(views_.size());
  double z_max = 0;
  for (size_t v = 0; v < views_.size(); ++v) {
    const LayeredDepthView& view = views_[v].depth;
    const Eigen::Matrix3d k_source = view.camera.K();
    const Rigid3 source_from_novel = views_[v].cam_from_world * cam_from_world.Inverse();
    const Eigen::Matrix3d r_rel = source_from_novel.RotationMatrix();
    const Eigen::Vector3d t_rel = source_from_novel.translation;
    const Rigid3 novel_from_source = cam_from_world * views_[v].cam_from_world.Inverse();
    struct Sorted {
      double depth;
      int segment;
      std::array<float, kFloatsPerInstance> data;
    };
    std::vector<Sorted> sorted;
    if (std::all_of(view_boxes[v].begin(), view_boxes[v].end(), [](const cv::Rect& r) { return r.empty(); })) continue;
    for (int s : textures_[v].kept_segments) {
      const DepthSegment& seg = view.segments[s];
      const Eigen::Vector3d plane_source =
          k_source.transpose() * Eigen::Vector3d(seg.inv_depth_a, seg.inv_depth_b, seg.inv_depth_c);
      // The output camera on the plane or beyond it would see the surface's back (segment_raster.cc).
      const double denominator = 1.0 - plane_source.dot(t_rel);
      if (!(denominator > 1e-12)) continue;
      const Eigen::Vector3d plane_novel = r_rel.transpose() * plane_source / denominator;
      const Eigen::Vector3d inv_depth_novel = k_novel.inverse().transpose() * plane_novel;
      const Eigen::Matrix3d h = k_source * (r_rel + t_rel * plane_novel.transpose()) * k_novel.inverse();
      const double x0 = seg.bbox.x - 1, x1 = seg.bbox.x + seg.bbox.width, y0 = seg.bbox.y - 1,
                   y1 = seg.bbox.y + seg.bbox.height;
      const std::array<Eigen::Vector2d, 4> corners = {
          Eigen::Vector2d(x0, y0), Eigen::Vector2d(x1, y0), Eigen::Vector2d(x1, y1), Eigen::Vector2d(x0, y1)};
      Sorted item;
      item.segment = s;
      bool behind = false;
      for (int c = 0; c < 4 && !behind; ++c) {
        const double z_source = 1.0 / seg.InverseDepthAt(corners[c].x(), corners[c].y());
        const Eigen::Vector3d point =
            novel_from_source * (z_source * k_source.inverse() * Eigen::Vector3d(corners[c].x(), corners[c].y(), 1.0));
        if (point.z() <= kNearDepthM) {
          behind = true;
          break;
        }
        z_max = std::max(z_max, point.z());
        const Eigen::Vector3d projected = k_novel * point;
        item.data[2 * c] = static_cast<float>(projected.x() / projected.z());
        item.data[2 * c + 1] = static_cast<float>(projected.y() / projected.z());
      }
      if (behind) continue;
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) item.data[8 + 3 * r + c] = static_cast<float>(h(r, c));
      }
      for (int c = 0; c < 3; ++c) item.data[17 + c] = static_cast<float>(inv_depth_novel(c));
      item.data[20] = static_cast<float>(s);
      const double cx = seg.bbox.x + (seg.bbox.width - 1) / 2.0, cy = seg.bbox.y + (seg.bbox.height - 1) / 2.0;
      const double z_centre = 1.0 / seg.InverseDepthAt(cx, cy);
      const Eigen::Vector3d centre_novel =
          novel_from_source * (z_centre * k_source.inverse() * Eigen::Vector3d(cx, cy, 1.0));
      // Rounded to float as the CPU reference's key is, so that both break the same near-ties by
      // segment index (with seam skirts the order of two segments of one flat surface shows a
      // little).
      item.depth = static_cast<float>(centre_novel.z());
      // The CPU reference's fade of stretched segments (texture_stretch.h), from the same centre.
      float texture_weight = 1.0f;
      if (texture_stretch_.fade_from > 0) {
        const Eigen::Vector3d centre_px = k_novel * centre_novel;
        texture_weight = render::TextureWeight(
            render::TextureStretch(
                h, centre_px.head<2>() / centre_px.z(), k_novel(0, 0) / k_source(0, 0) * z_centre / centre_novel.z()),
            texture_stretch_);
        if (texture_weight <= 0) continue;
      }
      item.data[21] = texture_weight;
      sorted.push_back(item);
    }
    std::sort(sorted.begin(), sorted.end(), [](const Sorted& a, const Sorted& b) {
      return a.depth != b.depth ? a.depth < b.depth : a.segment < b.segment;
    });
    for (const Sorted& item : sorted) instances[v].insert(instances[v].end(), item.data.begin(), item.data.end());
  }
  const float z_scale = static_cast<float>(std::max(z_max, kNearDepthM) * 1.0001);
  clock.Mark(&stats_.setup_ms, /*finish_gl=*/false);

  // One buffer for every view's instances, uploaded once; each draw starts at its view's first.
  std::vector<float> all_instances;
  std::vector<size_t> first_instance(views_.size());
  for (size_t v = 0; v < views_.size(); ++v) {
    first_instance[v] = all_instances.size() / kFloatsPerInstance;
    all_instances.insert(all_instances.end(), instances[v].begin(), instances[v].end());
  }
  gl.Enable(GL_BLEND);
  gl.BlendEquation(GL_FUNC_ADD);
  gl.BlendFuncSeparate(GL_SRC_ALPHA_SATURATE, GL_ONE, GL_ONE, GL_ONE);
  if (segment_floor_ && segment_floor_program_.id() == 0) {
    PX_ASSIGN_OR_RETURN(segment_floor_program_,
                        BuildProgram(gl, "segments_floor", kSegmentVertexShader, kSegmentFloorFragmentShader));
  }
  p = segment_floor_ ? segment_floor_program_.id() : segment_program_.id();
  gl.UseProgram(p);
  gl.Uniform2f(gl.GetUniformLocation(p, "viewport_size"), static_cast<float>(width), static_cast<float>(height));
  gl.Uniform1f(gl.GetUniformLocation(p, "z_scale"), z_scale);
  BindTextureUnit(gl, p, "slot_views", 3, t->slot_views.id());
  gl.BindVertexArray(instance_vertex_array_.id());
  gl.BindBuffer(GL_ARRAY_BUFFER, instance_buffer_.id());
  gl.BufferData(GL_ARRAY_BUFFER,
                static_cast<GLsizeiptr>(all_instances.size() * sizeof(float)),
                all_instances.data(),
                GL_STREAM_DRAW);
  // Slot by slot (each rendering buffer its own two targets), each view drawn where it holds that
  // slot: a fragment blends into two targets, not six, and a view is rasterised only inside its
  // box for the slot.
  const float zero[4] = {0, 0, 0, 0};
  for (int k = 0; k < 3; ++k) {
    gl.BindFramebuffer(GL_FRAMEBUFFER, t->slot_fbo[k].id());
    gl.Disable(GL_SCISSOR_TEST);
    for (int a = 0; a < 2; ++a) gl.ClearBufferfv(GL_COLOR, a, zero);
    gl.Enable(GL_SCISSOR_TEST);
    gl.Uniform1i(gl.GetUniformLocation(p, "slot"), k);
    for (size_t v = 0; v < views_.size(); ++v) {
      const cv::Rect& box = view_boxes[v][k];
      if (instances[v].empty() || box.empty()) continue;
      gl.Scissor(box.x, box.y, box.width, box.height);
      BindTextureUnit(gl, p, "texels", 0, textures_[v].texels.id());
      gl.Uniform1f(gl.GetUniformLocation(p, "view_index"), static_cast<float>(v));
      PointInstanceAttributes(gl, first_instance[v]);
      gl.DrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, static_cast<GLsizei>(instances[v].size() / kFloatsPerInstance));
      ++stats_.draws;
    }
  }
  gl.Disable(GL_SCISSOR_TEST);
  gl.Disable(GL_BLEND);
  stats_.instances = static_cast<int>(all_instances.size() / kFloatsPerInstance);
  clock.Mark(&stats_.segments_ms, /*finish_gl=*/true);

  // Pass 3: the soft z resolve.
  gl.BindFramebuffer(GL_FRAMEBUFFER, t->resolve_fbo.id());
  gl.UseProgram(resolve_program_.id());
  p = resolve_program_.id();
  const char* colour_names[3] = {"colour_slot0", "colour_slot1", "colour_slot2"};
  const char* depth_names[3] = {"depth_slot0", "depth_slot1", "depth_slot2"};
  for (int k = 0; k < 3; ++k) {
    BindTextureUnit(gl, p, colour_names[k], k, t->colour[k].id());
    BindTextureUnit(gl, p, depth_names[k], 3 + k, t->depth[k].id());
  }
  BindTextureUnit(gl, p, "slot_weights", 6, t->slot_weights.id());
  gl.Uniform1f(gl.GetUniformLocation(p, "z_scale"), z_scale);
  gl.Uniform1f(gl.GetUniformLocation(p, "rho"), static_cast<float>(rho_m_));
  gl.Uniform1f(gl.GetUniformLocation(p, "gamma"), static_cast<float>(rho_m_ * soft_z_gamma_fraction_));
  gl.BindVertexArray(empty_vertex_array_.id());
  gl.DrawArrays(GL_TRIANGLES, 0, 3);

  clock.Mark(&stats_.resolve_ms, /*finish_gl=*/true);
  RawFrame raw;
  raw.colour_alpha.create(height, width, CV_32FC4);
  ReadAttachment(gl, 0, width, height, GL_RGBA, GL_FLOAT, raw.colour_alpha.data);
  if (with_slots) {  // Coverage needs alpha only
    raw.depth.create(height, width, CV_32F);
    ReadAttachment(gl, 1, width, height, GL_RED, GL_FLOAT, raw.depth.data);
  }
  if (with_slots) {
    gl.BindFramebuffer(GL_FRAMEBUFFER, t->weights_fbo.id());
    raw.slot_views.create(height, width, CV_32FC4);
    raw.slot_weights.create(height, width, CV_32FC4);
    ReadAttachment(gl, 0, width, height, GL_RGBA, GL_FLOAT, raw.slot_views.data);
    ReadAttachment(gl, 1, width, height, GL_RGBA, GL_FLOAT, raw.slot_weights.data);
  }
  clock.Mark(&stats_.readback_ms, /*finish_gl=*/false);
  gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
  gl.BindVertexArray(0);
  const std::string errors = DrainGlErrors(gl);
  if (!errors.empty())
    return InternalError("gl renderer: a " + std::to_string(width) + "x" + std::to_string(height) + " frame raised " +
                         errors);
  return raw;
}

std::vector<GlSceneRenderer::SlotBoxes> GlSceneRenderer::ViewBoxes(const CameraModel& camera,
                                                                   const Rigid3& cam_from_world) const {
  constexpr int kGrid = 32;
  const Eigen::Matrix3d dir_from_pixel = cam_from_world.RotationMatrix().transpose() * camera.K().inverse();
  const Eigen::Vector3d centre = CameraCentre(cam_from_world);
  const double cell_x = static_cast<double>(camera.width) / kGrid, cell_y = static_cast<double>(camera.height) / kGrid;
  std::vector<SlotBoxes> boxes(views_.size());
  const cv::Rect frame(0, 0, camera.width, camera.height);
  for (int gy = 0; gy <= kGrid; ++gy) {
    for (int gx = 0; gx <= kGrid; ++gx) {
      const Eigen::Vector3d pixel(
          std::min(gx * cell_x, camera.width - 1.0), std::min(gy * cell_y, camera.height - 1.0), 1);
      const std::array<int, 3> slots = SlotViewsAt(mesh_, MeshPointOfRay(mesh_, centre, dir_from_pixel * pixel));
      for (int k = 0; k < 3; ++k) {
        if (slots[k] < 0) continue;
        const cv::Rect cell(static_cast<int>(std::floor(pixel.x() - cell_x - 1)),
                            static_cast<int>(std::floor(pixel.y() - cell_y - 1)),
                            static_cast<int>(std::ceil(2 * cell_x + 3)),
                            static_cast<int>(std::ceil(2 * cell_y + 3)));
        cv::Rect& box = boxes[slots[k]][k];
        box = box.empty() ? (cell & frame) : ((box | cell) & frame);
      }
    }
  }
  return boxes;
}

StatusOr<FrameRender> GlSceneRenderer::Render(const VirtualCamera& camera) {
  PX_RETURN_IF_ERROR(camera.Validate());
  ScopedCurrent current(context_.get());
  PX_RETURN_IF_ERROR(current.status());
  PX_ASSIGN_OR_RETURN(RawFrame raw,
                      RenderRaw(camera.camera, camera.cam_from_world, /*with_slots=*/true, viewing_weight_exponent_));
  PassClock clock(context_->gl(), time_passes_);
  const int width = camera.camera.width, height = camera.camera.height;
  FrameRender frame;
  cv::Mat colour(height, width, CV_32FC3);  // 0..255, as the CPU reference keeps it until the end
  frame.depth_m.create(height, width, CV_32F);
  frame.coverage.create(height, width, CV_8U);
  // Soft edges with too little alpha to count as covered: blended over the hole fill below.
  struct Partial {
    cv::Point at;
    float alpha;
    cv::Vec3f colour;
  };
  std::vector<Partial> partial;
  std::vector<double> view_weight(views_.size(), 0.0);
  for (int y = 0; y < height; ++y) {
    const cv::Vec4f* ca = raw.colour_alpha.ptr<cv::Vec4f>(y);
    const float* d = raw.depth.ptr<float>(y);
    const cv::Vec4f* sv = raw.slot_views.ptr<cv::Vec4f>(y);
    const cv::Vec4f* sw = raw.slot_weights.ptr<cv::Vec4f>(y);
    uint8_t* coverage = frame.coverage.ptr<uint8_t>(y);
    cv::Vec3f* c = colour.ptr<cv::Vec3f>(y);
    float* depth = frame.depth_m.ptr<float>(y);
    for (int x = 0; x < width; ++x) {
      const float alpha = ca[x][3];
      const bool covered = alpha >= 0.5f;
      coverage[x] = covered ? 255 : 0;
      c[x] = covered ? cv::Vec3f(ca[x][0], ca[x][1], ca[x][2]) : cv::Vec3f(0, 0, 0);
      depth[x] = covered ? d[x] : 0.0f;
      if (!covered && alpha > 0) partial.push_back({cv::Point(x, y), alpha, cv::Vec3f(ca[x][0], ca[x][1], ca[x][2])});
      for (int k = 0; k < 3; ++k) {
        const int view = static_cast<int>(std::lround(sv[x][k]));
        if (view >= 0 && view < static_cast<int>(views_.size())) view_weight[view] += sw[x][k];
      }
    }
  }
  const double holes = static_cast<double>(width) * height - cv::countNonZero(frame.coverage);
  frame.holes.width = width;
  frame.holes.height = height;
  frame.holes.hole_ratio = holes / (static_cast<double>(width) * height);
  frame.holes.hole_score = HoleScore(frame.coverage);
  stats_.other_view_pixels = 0;
  if (holes > 0) {  // the CPU reference's preview rule (ALGORITHM.md 6): other views, then reverse soft z
    cv::Mat known = frame.coverage.clone();
    if (holes_from_other_views_) {
      stats_.other_view_pixels = CoverHolesFromOtherViews(camera, raw, &known, &colour, &frame.depth_m);
    }
    if (border_holes_.enabled) FillBorderHoles(FrameSides{}, border_holes_, &known, &colour, &frame.depth_m);
    FillHolesReverseSoftZ(
        SoftZ(rho_m_, soft_z_gamma_fraction_), hole_window_radius_px_, 0, &known, &colour, &frame.depth_m);
  }
  // A soft edge with nothing behind it keeps its share over the fill (ALGORITHM.md 6).
  for (const Partial& p : partial) {
    cv::Vec3f& out = colour.at<cv::Vec3f>(p.at);
    out = p.alpha * p.colour + (1 - p.alpha) * out;
  }
  // Colour effects and depth of field (ALGORITHM.md 7, 8): the CPU reference's passes on the
  // read-back frame, not yet in shaders (README.md).
  ApplyColorEffects(camera.effects, camera.camera, camera.cam_from_world, frame.depth_m, &colour);
  if (camera.aperture_m > 0) {
    ApplyPreviewDepthOfField(camera.aperture_m, camera.focus_depth_m, camera.camera.fx, frame.depth_m, &colour);
  }
  colour.convertTo(frame.bgr, CV_8UC3);
  clock.Mark(&stats_.post_ms, /*finish_gl=*/false);
  std::vector<int> order;
  for (size_t v = 0; v < views_.size(); ++v) {
    if (view_weight[v] > 0) order.push_back(static_cast<int>(v));
  }
  std::sort(order.begin(), order.end(), [&](int a, int b) { return view_weight[a] > view_weight[b]; });
  for (int v : order) frame.sources.push_back(views_[v].depth.id);
  return frame;
}

const LayeredScene* GlSceneRenderer::OtherViewsScene() {
  if (other_views_scene_ != nullptr || other_views_scene_failed_) return other_views_scene_.get();
  std::vector<View> poses;               // LayeredScene reads the ids and poses only
  std::vector<LayeredDepthView> layers;  // shallow copies
  for (size_t v = 0; v < views_.size(); ++v) {
    poses.push_back({views_[v].depth.id, cv::Mat(), views_[v].depth.camera, views_[v].cam_from_world});
    layers.push_back(views_[v].depth);
  }
  // views_ carry the seam skirts already (Upload).
  RenderOptions scene_options;
  scene_options.soft_z_gamma_fraction = soft_z_gamma_fraction_;
  scene_options.hole_window_radius_px = hole_window_radius_px_;
  scene_options.seam_skirts.max_step = 0;
  StatusOr<LayeredScene> scene = LayeredScene::Create(poses, layers, scene_options);
  if (!scene.ok()) {
    other_views_scene_failed_ = true;
    const std::string warning =
        "holes are filled from their borders only: no CPU scene for drawing them from other "
        "views (" +
        scene.status().message() + ")";
    Logger("render")->warn("gl renderer: {}", warning);
    warnings_.push_back(warning);
    return nullptr;
  }
  other_views_scene_ = std::make_unique<LayeredScene>(std::move(scene).value());
  // The scene leaves out views without a drawable segment: GL indices map to it by id.
  scene_view_of_.assign(views_.size(), -1);
  for (size_t v = 0; v < views_.size(); ++v) {
    for (size_t s = 0; s < other_views_scene_->views().size(); ++s) {
      if (other_views_scene_->views()[s].id == views_[v].depth.id) scene_view_of_[v] = static_cast<int>(s);
    }
  }
  return other_views_scene_.get();
}

int GlSceneRenderer::CoverHolesFromOtherViews(
    const VirtualCamera& camera, const RawFrame& raw, cv::Mat* known, cv::Mat* colour, cv::Mat* depth) {
  // Frames whose holes the reverse soft z's window closes whole need nothing, not even the scene.
  cv::Mat large;
  const cv::Rect crop = LargeHoles(*known, hole_window_radius_px_, &large);
  if (crop.empty()) return 0;
  const LayeredScene* scene = OtherViewsScene();
  if (scene == nullptr) return 0;
  // The read-back slots as the scene's ViewSlots, where the step reads them (holes in the box).
  const int width = camera.camera.width;
  hole_slots_.resize(static_cast<size_t>(width) * camera.camera.height);
  for (int y = crop.y; y < crop.y + crop.height; ++y) {
    const cv::Vec4f* sv = raw.slot_views.ptr<cv::Vec4f>(y);
    const cv::Vec4f* sw = raw.slot_weights.ptr<cv::Vec4f>(y);
    const uint8_t* k = known->ptr<uint8_t>(y);
    ViewSlots* slots = hole_slots_.data() + static_cast<size_t>(y) * width;
    for (int x = crop.x; x < crop.x + crop.width; ++x) {
      if (k[x] != 0) continue;
      slots[x] = ViewSlots();
      for (int i = 0; i < 3; ++i) {
        const int view = static_cast<int>(std::lround(sv[x][i]));
        if (view < 0 || view >= static_cast<int>(views_.size()) || scene_view_of_[view] < 0) continue;
        slots[x].view[i] = static_cast<uint8_t>(scene_view_of_[view]);
        slots[x].weight[i] = sw[x][i];
      }
    }
  }
  FrameComposite composite;  // the read-back frame's colour and depth, drawn into in place
  composite.colour = *colour;
  composite.depth = *depth;
  return CoverLargeHolesFromOtherViews(*scene,
                                       camera.camera,
                                       camera.cam_from_world,
                                       hole_slots_,
                                       RenderQuality::kPreview,
                                       RenderOptions{}.covered_alpha,
                                       texture_stretch_,
                                       large,
                                       crop,
                                       known,
                                       &composite);
}

StatusOr<CoverageReport> GlSceneRenderer::Coverage(const CameraModel& camera, const Rigid3& cam_from_world) {
  VirtualCamera check;
  check.camera = camera;
  check.cam_from_world = cam_from_world;
  PX_RETURN_IF_ERROR(check.Validate());
  ScopedCurrent current(context_.get());
  PX_RETURN_IF_ERROR(current.status());
  PX_ASSIGN_OR_RETURN(RawFrame raw,
                      RenderRaw(camera,
                                cam_from_world,
                                /*with_slots=*/false,
                                /*weight_exponent=*/1.0));  // Coverage's weights: the paper's
  cv::Mat coverage(camera.height, camera.width, CV_8U);
  for (int y = 0; y < camera.height; ++y) {
    const cv::Vec4f* ca = raw.colour_alpha.ptr<cv::Vec4f>(y);
    for (int x = 0; x < camera.width; ++x) coverage.at<uint8_t>(y, x) = ca[x][3] >= 0.5f ? 255 : 0;
  }
  CoverageReport report;
  report.width = camera.width;
  report.height = camera.height;
  report.hole_ratio = 1.0 - cv::countNonZero(coverage) / (static_cast<double>(camera.width) * camera.height);
  report.hole_score = HoleScore(coverage);
  return report;
}

}  // namespace px::render::gl
