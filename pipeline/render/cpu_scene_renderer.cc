#include "pipeline/render/cpu_scene_renderer.h"

#include <algorithm>
#include <chrono>
#include <string>

#include <opencv2/imgproc.hpp>

#include "pipeline/core/log.h"
#include "pipeline/core/stage_clock.h"
#include "pipeline/render/color_effects.h"
#include "pipeline/render/compositor.h"
#include "pipeline/render/depth_of_field.h"
#include "pipeline/render/exemplar_inpaint.h"
#include "pipeline/render/hole_fill.h"
#include "pipeline/render/layered_from_depth.h"
#include "pipeline/render/segment_raster.h"

namespace px {
namespace {

cv::Mat ToBgr8(const cv::Mat& colour) {
  cv::Mat bgr;
  colour.convertTo(bgr, CV_8UC3);  // rounds to nearest and saturates
  return bgr;
}

CoverageReport MeasureCoverage(const cv::Mat& coverage) {
  CoverageReport report;
  report.width = coverage.cols;
  report.height = coverage.rows;
  const double total = static_cast<double>(coverage.total());
  report.hole_ratio = 1.0 - cv::countNonZero(coverage) / total;
  report.hole_score = report.hole_ratio > 0 ? render::HoleScore(coverage) : 0.0;
  return report;
}

// Coverage() at or below this fraction of the sources' focal length draws the coarse scene, whose
// segments are 64 source pixels wide (8 output pixels at the direction stage's 1/8 size).
constexpr double kCoarseScale = 0.25;
// Made at a quarter of the views' resolution (cheap to make: 16x fewer pixels) with 16 px blocks:
// a set-up per segment is most of a 1/8-size Coverage(), and 16 px blocks (4x fewer than 8 px)
// agree with the full-size coverage on as many viewpoints (direction_benchmark's
// BM_SearchProbeAgreement: 95, 97, 98 % on the 0, 1, 2-face shots either way; 32 px: 94, 97, 97).
constexpr double kCoarseViewScale = 0.25;
constexpr int kCoarseBlockPx = 16;

// The scene again with each view's front-layer depth, sampled at kCoarseViewScale, re-segmented
// into kCoarseBlockPx blocks (colours are not needed for coverage). Null, with the reason logged,
// when it cannot be made.
std::unique_ptr<render::LayeredScene> MakeCoarseScene(const std::vector<View>& views,
                                                      const std::vector<LayeredDepthView>& layers,
                                                      const RenderOptions& options) {
  LayeredFromDepthOptions coarse;
  coarse.block_px = kCoarseBlockPx;
  std::vector<View> coarse_views;
  for (const View& full : views) {
    View view;
    view.id = full.id;
    view.camera = full.camera.Scaled(kCoarseViewScale);
    view.cam_from_world = full.cam_from_world;
    coarse_views.push_back(std::move(view));
  }
  std::vector<LayeredDepthView> coarse_layers;
  coarse_layers.reserve(layers.size());
  for (const LayeredDepthView& layered : layers) {
    View view;
    view.id = layered.id;
    view.camera = layered.camera.Scaled(kCoarseViewScale);
    view.image = cv::Mat::zeros(view.camera.height, view.camera.width, CV_8UC3);
    DepthMap depth;
    depth.id = layered.id;
    cv::resize(layered.ToDepthMap().depth_m, depth.depth_m, view.image.size(), 0, 0, cv::INTER_NEAREST);
    StatusOr<LayeredDepthView> made = LayeredDepthFromDepthMap(view, depth, coarse);
    if (!made.ok()) {
      Logger("render")->debug("no coarse scene for Coverage(): {}", made.status().ToString());
      return nullptr;
    }
    coarse_layers.push_back(std::move(made).value());
  }
  StatusOr<render::LayeredScene> scene = render::LayeredScene::Create(coarse_views, coarse_layers, options);
  if (!scene.ok()) {
    Logger("render")->debug("no coarse scene for Coverage(): {}", scene.status().ToString());
    return nullptr;
  }
  return std::make_unique<render::LayeredScene>(std::move(scene).value());
}

}  // namespace

StatusOr<std::unique_ptr<CpuSceneRenderer>> CpuSceneRenderer::Create(const std::vector<View>& views,
                                                                     const std::vector<LayeredDepthView>& layers,
                                                                     const RenderOptions& options) {
  PX_ASSIGN_OR_RETURN(render::LayeredScene scene, render::LayeredScene::Create(views, layers, options));
  const auto log = Logger("render");
  for (const std::string& warning : scene.warnings()) log->warn("{}", warning);
  log->debug("cpu renderer: {} views in the mesh, {} triangles, depth range {:.3f} m", scene.views().size(),
             scene.mesh().triangles().size(), scene.depth_range_m());
  const Clock::time_point start = Clock::now();
  std::unique_ptr<render::LayeredScene> coarse = MakeCoarseScene(views, layers, options);
  // The coarse scene must take the same views in the same order (the mesh indexes them).
  if (coarse != nullptr && coarse->views().size() != scene.views().size()) coarse.reset();
  log->debug("coarse scene for Coverage(): {} in {:.1f} ms", coarse == nullptr ? "none" : "made", MsSince(start));
  double min_focal_px = 0;
  for (const render::SceneView& view : scene.views()) {
    const double focal = std::min(view.camera.fx, view.camera.fy);
    min_focal_px = min_focal_px == 0 ? focal : std::min(min_focal_px, focal);
  }
  auto renderer =
      std::unique_ptr<CpuSceneRenderer>(new CpuSceneRenderer(std::move(scene), std::move(coarse), options));
  renderer->min_source_focal_px_ = min_focal_px;
  return renderer;
}

Status CpuSceneRenderer::CheckCamera(const CameraModel& camera, const Rigid3& cam_from_world) const {
  PX_RETURN_IF_ERROR(camera.Validate().WithContext("render: camera"));
  if (camera.HasDistortion()) return InvalidArgumentError("render: camera must be a pinhole without distortion");
  if (!cam_from_world.rotation.coeffs().allFinite() || !cam_from_world.translation.allFinite()) {
    return InvalidArgumentError("render: camera pose is not finite");
  }
  const double pixels = static_cast<double>(camera.width) * camera.height;
  if (pixels > options_.max_output_pixels) {
    return InvalidArgumentError("render: output " + std::to_string(camera.width) + "x" + std::to_string(camera.height) +
                                " exceeds render.max_output_pixels " + std::to_string(options_.max_output_pixels));
  }
  return OkStatus();
}

CpuSceneRenderer::Core CpuSceneRenderer::RenderCore(const CameraModel& camera, const Rigid3& cam_from_world,
                                                    const std::vector<ColorEffect>& effects, RenderQuality quality,
                                                    bool inpaint) {
  const int width = camera.width, height = camera.height;
  Clock::time_point start = Clock::now();
  scene_.mesh().ComputeWeights(camera, cam_from_world, &slots_);
  stats_.weights_ms += MsSince(start);

  start = Clock::now();
  const std::vector<render::FrameView> frame_views = render::SetUpFrame(scene_, camera, cam_from_world, slots_);
  stats_.setup_ms += MsSince(start);
  stats_.views_drawn = static_cast<int>(frame_views.size());
  stats_.segments_drawn = 0;
  for (const render::FrameView& fv : frame_views) stats_.segments_drawn += static_cast<int>(fv.segments.size());

  start = Clock::now();
  render::FrameComposite composite;
  if (quality == RenderQuality::kOffline) {
    render::CompositeOffline(scene_, frame_views, slots_, width, height, &composite);
  } else {
    render::CompositePreview(scene_, frame_views, slots_, width, height, true, &composite);
  }
  stats_.composite_ms += MsSince(start);
  stats_.fragments += composite.fragments;

  start = Clock::now();
  Core core;
  core.coverage = composite.alpha >= options_.covered_alpha;
  cv::Mat known = core.coverage.clone();
  // Partly covered holes keep their share of colour over the fill (section 6).
  struct Partial {
    cv::Point at;
    float alpha;
    cv::Vec3f colour;
  };
  std::vector<Partial> partial;
  for (int y = 0; y < height; ++y) {
    const float* a = composite.alpha.ptr<float>(y);
    const uint8_t* k = known.ptr<uint8_t>(y);
    for (int x = 0; x < width; ++x) {
      if (k[x] == 0 && a[x] > 0) partial.push_back({{x, y}, a[x], composite.colour.at<cv::Vec3f>(y, x)});
    }
  }
  stats_.hole_pixels = width * height - cv::countNonZero(known);
  const render::SoftZ& soft_z = scene_.soft_z();
  const int radius = options_.hole_window_radius_px;
  if (stats_.hole_pixels > 0) {
    if (inpaint) {
      const cv::Mat small = render::SmallHoles(known, radius);
      const render::HoleFillReport first =
          render::FillHolesReverseSoftZ(soft_z, radius, 1, &known, &composite.colour, &composite.depth, &small);
      stats_.small_hole_pixels = first.first_pass;
      render::InpaintOptions inpaint_options;
      inpaint_options.patch_radius_px = options_.inpaint_patch_radius_px;
      inpaint_options.window_radius_px = options_.inpaint_window_radius_px;
      inpaint_options.depth_radius_px = radius;
      const render::InpaintReport inpainted = render::InpaintDepthAware(soft_z, inpaint_options, known == 0, &known,
                                                                        &composite.colour, &composite.depth);
      stats_.inpainted_pixels = inpainted.pixels - inpainted.fallback_pixels;
      stats_.propagated_pixels = inpainted.fallback_pixels;
    }
    const render::HoleFillReport rest =
        render::FillHolesReverseSoftZ(soft_z, radius, 0, &known, &composite.colour, &composite.depth);
    if (!inpaint) stats_.small_hole_pixels = rest.first_pass;
    stats_.propagated_pixels += inpaint ? rest.first_pass + rest.later_passes : rest.later_passes;
  }
  for (const Partial& p : partial) {
    cv::Vec3f& c = composite.colour.at<cv::Vec3f>(p.at);
    c = p.alpha * p.colour + (1.0f - p.alpha) * c;
  }
  stats_.holes_ms += MsSince(start);

  start = Clock::now();
  render::ApplyColorEffects(effects, camera, cam_from_world, composite.depth, &composite.colour);
  stats_.effects_ms += MsSince(start);

  std::vector<std::pair<double, ViewId>> by_weight;
  for (const render::FrameView& fv : frame_views) by_weight.emplace_back(-fv.weight_sum, scene_.views()[fv.view].id);
  std::sort(by_weight.begin(), by_weight.end());
  for (const auto& [weight, id] : by_weight) core.sources.push_back(id);
  core.colour = composite.colour;
  core.depth = composite.depth;
  return core;
}

StatusOr<FrameRender> CpuSceneRenderer::Render(const VirtualCamera& camera) {
  PX_RETURN_IF_ERROR(camera.Validate());
  PX_RETURN_IF_ERROR(CheckCamera(camera.camera, camera.cam_from_world));
  const Clock::time_point start = Clock::now();
  stats_ = CpuFrameStats();
  const bool offline = options_.quality == RenderQuality::kOffline;
  Core core = RenderCore(camera.camera, camera.cam_from_world, camera.effects, options_.quality, offline);
  FrameRender frame;
  if (camera.aperture_m > 0 && offline) {
    // Synthetic aperture: the average of jittered viewpoints registered on the focal plane.
    const std::vector<render::ApertureViewpoint> viewpoints = render::ApertureViewpoints(
        camera.camera, camera.cam_from_world, camera.aperture_m, camera.focus_depth_m, options_.aperture_samples);
    cv::Mat sum = cv::Mat::zeros(core.colour.size(), CV_32FC3);
    for (const render::ApertureViewpoint& v : viewpoints) {
      const Core sample = RenderCore(v.camera, v.cam_from_world, camera.effects, RenderQuality::kOffline, false);
      sum += sample.colour;
    }
    stats_.aperture_samples = static_cast<int>(viewpoints.size());
    core.colour = sum / static_cast<double>(viewpoints.size());
  } else if (camera.aperture_m > 0) {
    const Clock::time_point dof_start = Clock::now();
    const render::DepthOfFieldReport dof = render::ApplyPreviewDepthOfField(
        camera.aperture_m, camera.focus_depth_m, camera.camera.fx, core.depth, &core.colour);
    stats_.silhouette_pixels = dof.silhouette_pixels;
    stats_.effects_ms += MsSince(dof_start);
  }
  frame.bgr = ToBgr8(core.colour);
  frame.depth_m = core.depth;
  frame.coverage = core.coverage;
  frame.holes = MeasureCoverage(core.coverage);
  frame.sources = std::move(core.sources);
  stats_.total_ms = MsSince(start);
  Logger("render")->debug(
      "cpu {} frame {}x{}: {} views, {} segments; weights {:.1f} ms, setup {:.1f} ms, composite {:.1f} ms, "
      "holes {:.1f} ms ({:.2f}%), effects {:.1f} ms; {:.1f} ms in all",
      RenderQualityName(options_.quality), camera.camera.width, camera.camera.height, stats_.views_drawn,
      stats_.segments_drawn, stats_.weights_ms, stats_.setup_ms, stats_.composite_ms, stats_.holes_ms,
      100 * frame.holes.hole_ratio, stats_.effects_ms, stats_.total_ms);
  return frame;
}

StatusOr<CoverageReport> CpuSceneRenderer::Coverage(const CameraModel& camera, const Rigid3& cam_from_world) {
  PX_RETURN_IF_ERROR(CheckCamera(camera, cam_from_world));
  const bool coarse = coarse_scene_ != nullptr && std::max(camera.fx, camera.fy) <= kCoarseScale * min_source_focal_px_;
  const render::LayeredScene& scene = coarse ? *coarse_scene_ : scene_;
  std::vector<render::ViewSlots> slots;  // this call's own: calls may run side by side
  scene.mesh().ComputeWeights(camera, cam_from_world, &slots);
  const std::vector<render::FrameView> frame_views = render::SetUpFrame(scene, camera, cam_from_world, slots);
  render::FrameComposite composite;
  render::CompositePreview(scene, frame_views, slots, camera.width, camera.height, false, &composite);
  return MeasureCoverage(composite.alpha >= options_.covered_alpha);
}

}  // namespace px
