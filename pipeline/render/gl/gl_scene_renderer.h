// The real-time renderer of paper section 6.1 on headless GL (OSMesa or EGL), following
// pipeline/render/ALGORITHM.md: the view mesh (CPU, once per scene) and the per-pixel viewing
// weights in a shader; each view's segment images as textures and its segments drawn as
// instanced textured rectangles front to back into the three rendering buffers multiplexed by
// view (16-bit targets, saturating blend); the soft z-buffer of eq. (1) in a resolve shader;
// coverage, H(V), holes drawn again from other views (the CPU reference's CoverHolesFromOtherViews,
// on a CPU scene made on the first frame that needs it), hole filling (FillHolesReverseSoftZ),
// colour effects and the
// preview's depth of field (the CPU reference's passes, pipeline/render/color_effects.h and
// depth_of_field.h) on the CPU after the float read-back. 1D (collinear) rigs mesh as a strip
// (gl_view_mesh.h). Preview quality only: offline (paper 6.2) is the CPU back end's.
#pragma once

#include <array>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "pipeline/core/layered_depth.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/render/gl/gl_context.h"
#include "pipeline/render/gl/gl_objects.h"
#include "pipeline/render/gl/gl_view_mesh.h"
#include "pipeline/render/gl/view_texels.h"
#include "pipeline/render/render_options.h"
#include "pipeline/render/scene_renderer.h"
#include "pipeline/render/view_mesh.h"

namespace px::render {
class LayeredScene;
}  // namespace px::render

namespace px::render::gl {

struct GlSceneRendererOptions {
  GlContextOptions context;
  // RenderOptions::viewing_weight_exponent (the same default; (0, 1]).
  double viewing_weight_exponent = RenderOptions{}.viewing_weight_exponent;
  // RenderOptions::soft_z_gamma_fraction and hole_window_radius_px (the same defaults and ranges):
  // the soft z's gamma as a fraction of the scene's depth range, and the reverse soft z's window.
  double soft_z_gamma_fraction = RenderOptions{}.soft_z_gamma_fraction;
  int hole_window_radius_px = RenderOptions{}.hole_window_radius_px;
  // RenderOptions::holes_from_other_views (the same default): holes larger than the fill window
  // are drawn again on the CPU from the views the mesh did not blend there (hole_views.h), from a
  // CPU LayeredScene made on the first frame that needs it.
  bool holes_from_other_views = RenderOptions{}.holes_from_other_views;
  // RenderOptions::border_holes (the same default): holes at the frame's border carried out from
  // their inner edge before the reverse soft z, on the CPU after the read-back.
  render::BorderHoleFillOptions border_holes = RenderOptions{}.border_holes;
  // RenderOptions::seam_skirts (the same default): applied to the views' texels
  // once, on upload, as the CPU reference's LayeredScene applies them.
  SeamSkirtOptions seam_skirts = RenderOptions{}.seam_skirts;
  // RenderOptions::texture_stretch (the same default): stretched segments fade out.
  TextureStretchOptions texture_stretch = RenderOptions{}.texture_stretch;
  Status Validate() const;
};

// The GL options for `render` (every field that changes a preview frame), context left default.
GlSceneRendererOptions GlOptionsFrom(const RenderOptions& render);

// The last frame (Render or Coverage): what was drawn and, with set_time_passes(true), the
// process CPU time of each pass in ms (a glFinish after each GL pass, so llvmpipe's rasteriser
// threads count where they work; the finishes cost a little of the overlap).
struct GlFrameStats {
  int draws = 0;      // instanced draws: a view's segments into one rendering buffer
  int instances = 0;  // segment rectangles set up (all views)
  double weights_ms = 0, setup_ms = 0, segments_ms = 0, resolve_ms = 0, readback_ms = 0, post_ms = 0;
  int other_view_pixels = 0;  // Render: hole pixels drawn again from other views (in post_ms)
};

class GlSceneRenderer final : public SceneRenderer {
 public:
  // Creates the context, builds the view mesh and uploads every view's segment images. Bad
  // texels (non-finite or out-of-range weights, segment indices out of range) and bad segments
  // (non-finite planes, depth not positive over their rectangle) are dropped and counted in
  // warnings(). Errors: no context (the platforms' reasons), a view larger than the context's
  // GL_MAX_TEXTURE_SIZE, images of the wrong size or type (naming the view), shader errors.
  static StatusOr<std::unique_ptr<GlSceneRenderer>> Create(std::vector<PosedLayeredView> views,
                                                           const GlSceneRendererOptions& options = {});
  // The same on a context made already (ChooseRenderBackend's); it must not be current elsewhere.
  // options.context is not used.
  static StatusOr<std::unique_ptr<GlSceneRenderer>> Create(std::vector<PosedLayeredView> views,
                                                           std::unique_ptr<GlContext> context,
                                                           const GlSceneRendererOptions& options = {});
  ~GlSceneRenderer() override;

  std::string_view BackendName() const override { return context_->BackendName(); }
  StatusOr<FrameRender> Render(const VirtualCamera& camera) override;
  StatusOr<CoverageReport> Coverage(const CameraModel& camera, const Rigid3& cam_from_world) override;

  const GlContextInfo& context_info() const { return context_->info(); }
  const std::vector<std::string>& warnings() const { return warnings_; }
  double rho_m() const { return rho_m_; }
  const GlFrameStats& last_frame() const { return stats_; }
  void set_time_passes(bool on) { time_passes_ = on; }
  // Benchmarks only: the segment pass draws its rectangles with a shader that discards at once,
  // so its time is the rasteriser's floor (the frame is all holes).
  void set_segment_floor(bool on) { segment_floor_ = on; }

 private:
  struct ViewTextures {
    // Per texel (RGBA32UI): layer 0 and layer 1 as packed BGRA8 (weight in the top byte), then
    // their segment indices (-1 none): one fetch per texel of the masked bilinear sample.
    GlObject texels;
    std::vector<int> kept_segments;  // segments that survived sanitising
  };
  struct Targets {  // per output size
    GlObject slot_views, slot_weights, weights_fbo;
    GlObject colour[3], depth[3], slot_fbo[3];  // the three rendering buffers, one FBO each
    GlObject resolved_colour, resolved_depth, resolve_fbo;
  };
  // The resolved frame before hole filling: (B, G, R, alpha) and depth, CV_32FC4 and CV_32F.
  struct RawFrame {
    cv::Mat colour_alpha;
    cv::Mat depth;         // only with the slots (Render; Coverage needs alpha only)
    cv::Mat slot_views;    // CV_32FC4, only when asked for
    cv::Mat slot_weights;  // CV_32FC4
  };

  GlSceneRenderer() = default;
  Status Upload();
  StatusOr<Targets*> TargetsFor(int width, int height);
  // Per view and slot, the box of output pixels where it may hold that slot (empty: nowhere).
  using SlotBoxes = std::array<cv::Rect, 3>;
  std::vector<SlotBoxes> ViewBoxes(const CameraModel& camera, const Rigid3& cam_from_world) const;
  // weight_exponent: the viewing weights' (FlattenViewingWeights); Coverage() passes 1.
  StatusOr<RawFrame> RenderRaw(const CameraModel& camera,
                               const Rigid3& cam_from_world,
                               bool with_slots,
                               double weight_exponent);
  // The CPU reference's step before hole filling (ALGORITHM.md 6, hole_views.h) on the read-back
  // frame: holes larger than the fill window drawn again from other views into `colour` and
  // `depth`, marked in `known`. Returns the pixels covered.
  int CoverHolesFromOtherViews(
      const VirtualCamera& camera, const RawFrame& raw, cv::Mat* known, cv::Mat* colour, cv::Mat* depth);
  // The CPU scene for that step, made on first use (nullptr, once warned, when it cannot be).
  const LayeredScene* OtherViewsScene();

  std::unique_ptr<GlContext> context_;
  std::vector<PosedLayeredView> views_;
  std::vector<ViewTextures> textures_;
  GlViewMesh mesh_;
  std::vector<std::array<float, 4>> mesh_uniforms_;  // the weight shader's mesh (Upload)
  GlObject weights_program_, segment_program_, resolve_program_;
  GlObject segment_floor_program_;  // made on the first frame with set_segment_floor(true)
  GlObject empty_vertex_array_, instance_vertex_array_, instance_buffer_;
  std::map<std::pair<int, int>, Targets> targets_;
  double rho_m_ = 0;
  double median_depth_m_ = 0;
  std::vector<std::string> warnings_;
  GlFrameStats stats_;
  bool time_passes_ = false;
  bool segment_floor_ = false;
  double viewing_weight_exponent_ = 1;
  double soft_z_gamma_fraction_ = RenderOptions{}.soft_z_gamma_fraction;
  int hole_window_radius_px_ = RenderOptions{}.hole_window_radius_px;
  bool holes_from_other_views_ = true;
  render::BorderHoleFillOptions border_holes_;
  SeamSkirtOptions seam_skirts_;
  TextureStretchOptions texture_stretch_;
  // Holes from other views: the CPU scene made from views_ on first use, each GL view's index in
  // that scene (-1: the scene left it out), and the read-back slots turned into the scene's.
  std::unique_ptr<LayeredScene> other_views_scene_;
  bool other_views_scene_failed_ = false;
  std::vector<int> scene_view_of_;
  std::vector<ViewSlots> hole_slots_;
};

}  // namespace px::render::gl
