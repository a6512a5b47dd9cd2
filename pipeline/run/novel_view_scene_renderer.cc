#include "pipeline/run/novel_view_scene_renderer.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

namespace px {

StatusOr<std::unique_ptr<NovelViewSceneRenderer>> NovelViewSceneRenderer::Create(const std::vector<View>& views,
                                                                                  const std::vector<DepthMap>& depths,
                                                                                  const RenderOptions& options) {
  PX_ASSIGN_OR_RETURN(std::unique_ptr<NovelViewRenderer> full, NovelViewRenderer::Create(views, depths, options));
  return std::unique_ptr<NovelViewSceneRenderer>(new NovelViewSceneRenderer(views, depths, options, std::move(full)));
}

StatusOr<FrameRender> NovelViewSceneRenderer::Render(const VirtualCamera& camera) {
  PX_RETURN_IF_ERROR(camera.Validate());
  PX_ASSIGN_OR_RETURN(RenderResult result, full_->Render(camera.camera, camera.cam_from_world));
  FrameRender frame;
  frame.bgr = std::move(result.bgr);
  frame.depth_m = std::move(result.depth_m);
  frame.coverage = std::move(result.coverage);
  frame.holes.hole_ratio = result.hole_ratio;
  frame.holes.hole_score = result.hole_score;
  frame.holes.width = camera.camera.width;
  frame.holes.height = camera.camera.height;
  frame.sources = std::move(result.sources);
  return frame;
}

StatusOr<NovelViewRenderer*> NovelViewSceneRenderer::RendererForWidth(int width) {
  const int full_width = views_.front().camera.width;
  // Within 5 % of the views' size the full-size sources are as cheap as any.
  if (width >= 0.95 * full_width) return full_.get();
  auto found = reduced_.find(width);
  if (found != reduced_.end()) return found->second.get();
  const double factor = static_cast<double>(width) / full_width;
  std::vector<View> views;
  std::vector<DepthMap> depths;
  for (const View& view : views_) {
    View small;
    small.id = view.id;
    small.camera = view.camera.Scaled(factor);
    small.cam_from_world = view.cam_from_world;
    const cv::Size size(std::max(2, small.camera.width), std::max(2, small.camera.height));
    small.camera.width = size.width;
    small.camera.height = size.height;
    cv::resize(view.image, small.image, size, 0, 0, cv::INTER_AREA);
    views.push_back(std::move(small));
  }
  for (const DepthMap& depth : depths_) {
    const View* view = nullptr;
    for (const View& v : views) {
      if (v.id == depth.id) view = &v;
    }
    if (view == nullptr) continue;
    DepthMap small;
    small.id = depth.id;
    const cv::Size size(view->camera.width, view->camera.height);
    cv::resize(depth.depth_m, small.depth_m, size, 0, 0, cv::INTER_NEAREST);
    if (!depth.confidence.empty()) cv::resize(depth.confidence, small.confidence, size, 0, 0, cv::INTER_AREA);
    depths.push_back(std::move(small));
  }
  PX_ASSIGN_OR_RETURN(std::unique_ptr<NovelViewRenderer> renderer,
                      NovelViewRenderer::Create(views, depths, options_));
  NovelViewRenderer* raw = renderer.get();
  reduced_[width] = std::move(renderer);
  return raw;
}

StatusOr<CoverageReport> NovelViewSceneRenderer::Coverage(const CameraModel& camera, const Rigid3& cam_from_world) {
  PX_ASSIGN_OR_RETURN(NovelViewRenderer * renderer, RendererForWidth(camera.width));
  PX_ASSIGN_OR_RETURN(RenderResult result, renderer->Render(camera, cam_from_world));
  CoverageReport report;
  report.hole_ratio = result.hole_ratio;
  report.hole_score = result.hole_score;
  report.width = camera.width;
  report.height = camera.height;
  return report;
}

}  // namespace px
