// The CPU reference renderer of paper section 6 (ALGORITHM.md), a SceneRenderer back end ("cpu"):
// the view mesh's per-pixel viewing weights, segments drawn as textured rectangles into three
// rendering buffers, the soft z-buffer across them, reverse soft z hole filling, colour effects
// and circle-of-confusion depth of field (preview); or one soft z over all fragments, exemplar
// inpainting of large holes and a synthetic aperture (offline). Every pass runs in parallel with
// cv::parallel_for_. The GL back end (pipeline/render/gl) is checked against this one.
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "pipeline/core/layered_depth.h"
#include "pipeline/core/view.h"
#include "pipeline/render/compositor.h"
#include "pipeline/render/layered_scene.h"
#include "pipeline/render/render_options.h"
#include "pipeline/render/scene_renderer.h"
#include "pipeline/render/segment_raster.h"

namespace px {

// What the last Render() did, for logs, benchmarks and tests.
struct CpuFrameStats {
  int views_drawn = 0;        // views holding a slot somewhere in the frame
  int segments_drawn = 0;     // segments set up (after culling)
  long fragments = 0;         // fragments generated (each a segment's sample at a pixel that holds its view)
  int hole_pixels = 0;        // before filling
  int other_view_pixels = 0;  // holes covered by views the mesh did not blend there (hole_views.h)
  int small_hole_pixels = 0;  // filled by the 7x7 reverse soft z pass
  int propagated_pixels = 0;  // filled by the later passes (preview) or the blend fallback
  int inpainted_pixels = 0;   // filled by exemplar inpainting (offline)
  int silhouette_pixels = 0;  // depth of field: background pixels given blurred foreground
  int aperture_samples = 0;   // offline depth of field: viewpoints averaged
  double weights_ms = 0, setup_ms = 0, composite_ms = 0, holes_ms = 0, effects_ms = 0, total_ms = 0;
};

class CpuSceneRenderer final : public SceneRenderer {
 public:
  // Prepares the scene (render::LayeredScene::Create: errors name the view; bad content is
  // repaired and listed in warnings()).
  static StatusOr<std::unique_ptr<CpuSceneRenderer>> Create(const std::vector<View>& views,
                                                            const std::vector<LayeredDepthView>& layers,
                                                            const RenderOptions& options);

  std::string_view BackendName() const override { return "cpu"; }
  // Errors: the camera's (VirtualCamera::Validate), or an output above options.max_output_pixels.
  // A camera that sees no part of the scene gives a black frame with hole ratio 1, not an error.
  StatusOr<FrameRender> Render(const VirtualCamera& camera) override;
  // The preview's coverage (sections 3 to 5 without colour) at `camera`'s size. At a quarter of
  // the sources' focal length or less (the direction stage's reduced-size search) it draws the
  // coarse scene instead: the same depth as 32 px planar blocks (16x fewer segments to set up,
  // each still several output pixels wide), so its cost follows the output size. It keeps no
  // state between calls: calls may run on several threads at once, and beside Render().
  StatusOr<CoverageReport> Coverage(const CameraModel& camera, const Rigid3& cam_from_world) override;

  const render::LayeredScene& scene() const { return scene_; }
  const RenderOptions& options() const { return options_; }
  const std::vector<std::string>& warnings() const { return scene_.warnings(); }
  const CpuFrameStats& last_frame() const { return stats_; }
  // The scene Coverage() draws at reduced size (null when it could not be made: then the full one).
  const render::LayeredScene* coarse_scene() const { return coarse_scene_.get(); }

 private:
  CpuSceneRenderer(render::LayeredScene scene,
                   std::unique_ptr<render::LayeredScene> coarse_scene,
                   const RenderOptions& options)
      : scene_(std::move(scene)), coarse_scene_(std::move(coarse_scene)), options_(options) {}

  struct Core {            // one pinhole render: colour after hole filling and effects
    cv::Mat colour;        // CV_32FC3
    cv::Mat depth;         // CV_32F
    cv::Mat coverage;      // CV_8U
    CoverageReport holes;  // of `coverage`
    std::vector<ViewId> sources;
    cv::Mat double_image;  // CV_8U when measured (RenderOptions::measure_double_images)
  };
  Status CheckCamera(const CameraModel& camera, const Rigid3& cam_from_world) const;
  Core RenderCore(const CameraModel& camera,
                  const Rigid3& cam_from_world,
                  const std::vector<ColorEffect>& effects,
                  RenderQuality quality,
                  bool inpaint);

  render::LayeredScene scene_;
  std::unique_ptr<render::LayeredScene> coarse_scene_;  // for reduced-size Coverage()
  double min_source_focal_px_ = 0;
  RenderOptions options_;
  CpuFrameStats stats_;
  // Render()'s buffers, reused between frames (Coverage() keeps its own per call: it may run on
  // several threads at once).
  std::vector<render::ViewSlots> slots_;
  std::vector<render::FrameView> frame_views_;
  render::FrameComposite composite_;  // the preview's colour and alpha
};

}  // namespace px
