// The SceneRenderer interface (pipeline/render/scene_renderer.h) over the existing z-buffer
// NovelViewRenderer, so that the direction stage's viewpoint search measures real coverage until
// the segment-based CPU back end lands. Render() draws the pinhole frame (depth of field and
// colour effects are not drawn: the frame's report says so through BackendName "cpu-zbuffer").
// Coverage() renders from sources downsampled to the requested camera's size (one renderer per
// scale, built on first use), which is what makes hundreds of coverage probes per shot cheap.
#pragma once

#include <map>
#include <memory>
#include <vector>

#include "pipeline/core/view.h"
#include "pipeline/render/novel_view_renderer.h"
#include "pipeline/render/render_options.h"
#include "pipeline/render/scene_renderer.h"

namespace px {

class NovelViewSceneRenderer final : public SceneRenderer {
 public:
  // Keeps (shallow copies of) the views and depths; errors as NovelViewRenderer::Create.
  static StatusOr<std::unique_ptr<NovelViewSceneRenderer>> Create(const std::vector<View>& views,
                                                                  const std::vector<DepthMap>& depths,
                                                                  const RenderOptions& options);

  std::string_view BackendName() const override { return "cpu-zbuffer"; }
  StatusOr<FrameRender> Render(const VirtualCamera& camera) override;
  // Measured at the camera's own size. When it is smaller than the views, the sources are
  // downsampled by the same factor first (area-averaged colour, nearest depth so that no depth
  // is invented across an edge), so the cost falls with the square of the scale.
  StatusOr<CoverageReport> Coverage(const CameraModel& camera, const Rigid3& cam_from_world) override;

 private:
  NovelViewSceneRenderer(std::vector<View> views, std::vector<DepthMap> depths, const RenderOptions& options,
                         std::unique_ptr<NovelViewRenderer> full)
      : views_(std::move(views)), depths_(std::move(depths)), options_(options), full_(std::move(full)) {}
  StatusOr<NovelViewRenderer*> RendererForWidth(int width);

  std::vector<View> views_;
  std::vector<DepthMap> depths_;
  RenderOptions options_;
  std::unique_ptr<NovelViewRenderer> full_;
  std::map<int, std::unique_ptr<NovelViewRenderer>> reduced_;  // by source width
};

}  // namespace px
