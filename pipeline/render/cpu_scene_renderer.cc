#include "pipeline/render/cpu_scene_renderer.h"

#include <algorithm>
#include <chrono>
#include <opencv2/imgproc.hpp>
#include <string>

#include "pipeline/core/log.h"
#include "pipeline/core/stage_clock.h"
#include "pipeline/render/border_holes.h"
#include "pipeline/render/color_effects.h"
#include "pipeline/render/compositor.h"
#include "pipeline/render/depth_of_field.h"
#include "pipeline/render/exemplar_inpaint.h"
#include "pipeline/render/hole_fill.h"
#include "pipeline/render/hole_regions.h"
#include "pipeline/render/hole_views.h"
#include "pipeline/render/layered_from_depth.h"
#include "pipeline/render/segment_raster.h"

namespace px {
namespace {

cv::Mat ToBgr8(const cv::Mat& colour) {
  cv::Mat bgr(colour.size(), CV_8UC3);
  // Rounds to nearest and saturates; in stripes on every core (a 1200x800 frame is 3M values).
  cv::parallel_for_(cv::Range(0, colour.rows), [&](const cv::Range& rows) {
    colour.rowRange(rows.start, rows.end).convertTo(bgr.rowRange(rows.start, rows.end), CV_8UC3);
  });
  return bgr;
}

// cv::distanceTransform's 5x5 mask (H(V)) reaches 2 pixels from a hole at a step.
constexpr int kHoleScoreMarginPx = 2;

// Hole ratio and H(V) of `coverage`, H(V) summed over `regions` (render::HoleRegions with a margin
// of at least kHoleScoreMarginPx: the distances are the same there, every other pixel is covered
// and adds 0) and normalised by the whole frame.
CoverageReport MeasureCoverage(const cv::Mat& coverage, const std::vector<cv::Rect>& regions) {
  CoverageReport report;
  report.width = coverage.cols;
  report.height = coverage.rows;
  const double total = static_cast<double>(coverage.total());
  report.hole_ratio = 1.0 - cv::countNonZero(coverage) / total;
  for (const cv::Rect& region : regions) {
    report.hole_score += render::HoleScore(coverage(region)) * (static_cast<double>(region.area()) / total);
  }
  return report;
}

CoverageReport MeasureCoverage(const cv::Mat& coverage) {
  return MeasureCoverage(coverage, render::HoleRegions(coverage, kHoleScoreMarginPx));
}

struct HoleCounts {
  int small = 0, propagated = 0, inpainted = 0;
};

// A hole pixel with some alpha (a soft edge with nothing behind it), in its region's coordinates.
struct PartialPixel {
  cv::Point at;
  float alpha;
  cv::Vec3f colour;
};

// The partly covered hole pixels of `region` (section 6: they keep their share of colour over the
// fill), read before anything draws over the holes.
std::vector<PartialPixel> PartialPixelsIn(const cv::Rect& region,
                                          const cv::Mat& coverage,
                                          const render::FrameComposite& composite) {
  std::vector<PartialPixel> partial;
  for (int y = 0; y < region.height; ++y) {
    const float* a = composite.alpha.ptr<float>(region.y + y) + region.x;
    const uint8_t* k = coverage.ptr<uint8_t>(region.y + y) + region.x;
    const cv::Vec3f* c = composite.colour.ptr<cv::Vec3f>(region.y + y) + region.x;
    for (int x = 0; x < region.width; ++x) {
      if (k[x] == 0 && a[x] > 0) partial.push_back({{x, y}, a[x], c[x]});
    }
  }
  return partial;
}

// Fills the pixels of `region` (a render::HoleRegions box, or the whole frame) that `known` does
// not hold: holes at the frame's border carried out from their inner edge (border_holes.h), the
// rest by reverse soft z (section 6), after exemplar inpainting of the large holes when `inpaint`
// (offline, section 10; not at the image border: patches guess worse outside the sources' view);
// then the soft edges' `partial` colours go back over the fill.
HoleCounts FillHolesIn(const cv::Rect& region,
                       bool inpaint,
                       const RenderOptions& options,
                       const render::SoftZ& soft_z,
                       const cv::Mat& known_in_frame,
                       const std::vector<PartialPixel>& partial,
                       render::FrameComposite* composite) {
  HoleCounts counts;
  const int radius = options.hole_window_radius_px;
  cv::Mat known = known_in_frame(region).clone();
  cv::Mat colour = composite->colour(region), depth = composite->depth(region);
  if (cv::countNonZero(known) < static_cast<int>(known.total())) {
    if (inpaint) {
      const cv::Mat small = render::SmallHoles(known, radius);
      const render::HoleFillReport first =
          render::FillHolesReverseSoftZ(soft_z, radius, 1, &known, &colour, &depth, &small);
      counts.small = first.first_pass;
      render::InpaintOptions inpaint_options;
      inpaint_options.patch_radius_px = options.inpaint_patch_radius_px;
      inpaint_options.window_radius_px = options.inpaint_window_radius_px;
      inpaint_options.depth_radius_px = radius;
      inpaint_options.fill_border_holes = false;  // filled below: better outside the sources' view
      const render::InpaintReport inpainted =
          render::InpaintDepthAware(soft_z, inpaint_options, known == 0, &known, &colour, &depth);
      counts.inpainted = inpainted.pixels - inpainted.fallback_pixels;
      counts.propagated = inpainted.fallback_pixels;
    }
    if (options.border_holes.enabled) {
      render::FillBorderHoles(
          render::SidesOnFrameBorder(region, known_in_frame.size()), options.border_holes, &known, &colour, &depth);
    }
    const render::HoleFillReport rest = render::FillHolesReverseSoftZ(soft_z, radius, 0, &known, &colour, &depth);
    if (!inpaint) counts.small = rest.first_pass;
    counts.propagated += inpaint ? rest.first_pass + rest.later_passes : rest.later_passes;
  }
  for (const PartialPixel& p : partial) {
    cv::Vec3f& c = colour.at<cv::Vec3f>(p.at);
    c = p.alpha * p.colour + (1.0f - p.alpha) * c;
  }
  return counts;
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

// The scene again with each view's depth as drawn (its dominant layer's planes; not depth_m,
// which the depth stage holds to its swept range while a plane tilted past the range's end at an
// unmatched image border is drawn beyond it: a coarse scene made from depth_m would cover what the
// frame leaves open), sampled at kCoarseViewScale, re-segmented into kCoarseBlockPx blocks
// (colours are not needed for coverage). Null, with the reason logged, when it cannot be made.
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
    cv::resize(layered.DominantPlaneDepth(), depth.depth_m, view.image.size(), 0, 0, cv::INTER_NEAREST);
    StatusOr<LayeredDepthView> made = LayeredDepthFromDepthMap(view, depth, coarse);
    if (!made.ok()) {
      Logger("render")->debug("no coarse scene for Coverage(): {}", made.status().ToString());
      return nullptr;
    }
    coarse_layers.push_back(std::move(made).value());
  }
  // Without seam skirts (they close cracks in magnified renders; this scene only measures holes,
  // minified): its probes stay as they were before the skirts, at 5-10 % less CPU per call
  // (render_benchmark BM_Coverage), agreeing with the full-size verdict as often (direction_benchmark
  // BM_SearchProbeAgreement: 95, 97, 98 % without, 96, 97, 98 % with).
  RenderOptions coarse_options = options;
  coarse_options.seam_skirts.max_step = 0;
  StatusOr<render::LayeredScene> scene = render::LayeredScene::Create(coarse_views, coarse_layers, coarse_options);
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
  log->debug("cpu renderer: {} views in the mesh, {} triangles, depth range {:.3f} m",
             scene.views().size(),
             scene.mesh().triangles().size(),
             scene.depth_range_m());
  const StageClock::time_point start = StageClock::now();
  std::unique_ptr<render::LayeredScene> coarse = MakeCoarseScene(views, layers, options);
  // The coarse scene must take the same views in the same order (the mesh indexes them).
  if (coarse != nullptr && coarse->views().size() != scene.views().size()) coarse.reset();
  log->debug("coarse scene for Coverage(): {} in {:.1f} ms", coarse == nullptr ? "none" : "made", MsSince(start));
  double min_focal_px = 0;
  for (const render::SceneView& view : scene.views()) {
    const double focal = std::min(view.camera.fx, view.camera.fy);
    min_focal_px = min_focal_px == 0 ? focal : std::min(min_focal_px, focal);
  }
  auto renderer = std::unique_ptr<CpuSceneRenderer>(new CpuSceneRenderer(std::move(scene), std::move(coarse), options));
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

CpuSceneRenderer::Core CpuSceneRenderer::RenderCore(const CameraModel& camera,
                                                    const Rigid3& cam_from_world,
                                                    const std::vector<ColorEffect>& effects,
                                                    RenderQuality quality,
                                                    bool inpaint) {
  const int width = camera.width, height = camera.height;
  StageClock::time_point start = StageClock::now();
  scene_.mesh().ComputeWeights(camera, cam_from_world, &slots_, options_.viewing_weight_exponent);
  stats_.weights_ms += MsSince(start);

  start = StageClock::now();
  // Witnesses vote only in the preview's colour consensus (preview_compositor.cc).
  const ConsistentBlendOptions& consistent = options_.consistent_blend;
  const bool with_witnesses = quality == RenderQuality::kPreview && consistent.enabled &&
                              consistent.colour_apart_levels > consistent.colour_agree_levels;
  render::SetUpFrame(scene_, camera, cam_from_world, slots_, options_.texture_stretch, with_witnesses, &frame_views_);
  const std::vector<render::FrameView>& frame_views = frame_views_;
  stats_.setup_ms += MsSince(start);
  stats_.views_drawn = static_cast<int>(frame_views.size());
  stats_.segments_drawn = 0;
  for (const render::FrameView& fv : frame_views) stats_.segments_drawn += static_cast<int>(fv.segments.size());

  start = StageClock::now();
  // The preview reuses its colour and alpha buffers from frame to frame (15 MB of fresh pages a
  // 1200x800 frame otherwise); depth leaves with the frame, so it is always a new buffer.
  render::FrameComposite offline_composite;
  render::FrameComposite& composite = quality == RenderQuality::kPreview ? composite_ : offline_composite;
  composite.depth.release();
  if (quality == RenderQuality::kOffline) {
    render::CompositeOffline(scene_, frame_views, slots_, width, height, &composite);
  } else {
    render::BlendRules rules;
    const ConsistentBlendOptions& blend = options_.consistent_blend;
    rules.consistent = blend.enabled;
    rules.dominance_exponent = static_cast<float>(blend.dominance_exponent);
    rules.colour_agree_levels = static_cast<float>(blend.colour_agree_levels);
    rules.colour_apart_levels = static_cast<float>(blend.colour_apart_levels);
    rules.one_view_regions = blend.one_view_regions;
    rules.measure_double_images = options_.measure_double_images;
    const bool contested = rules.consistent || rules.measure_double_images;
    render::CompositePreview(
        scene_, frame_views, slots_, width, height, true, &composite, contested ? &rules : nullptr);
  }
  stats_.composite_ms += MsSince(start);
  stats_.fragments += composite.fragments;

  start = StageClock::now();
  Core core;
  core.coverage = composite.alpha >= options_.covered_alpha;
  stats_.hole_pixels = width * height - cv::countNonZero(core.coverage);
  const int radius = options_.hole_window_radius_px;
  // Hole filling works box by box on the holes' regions grown by the fill window (the windows
  // and the distances to covered pixels all lie inside them, so the result is the whole frame's;
  // exemplar inpainting searches wider: the whole frame), the boxes in parallel, with H(V), which
  // reads the coverage only, beside them.
  const std::vector<cv::Rect> regions = stats_.hole_pixels == 0 ? std::vector<cv::Rect>()
                                        : inpaint
                                            ? std::vector<cv::Rect>{cv::Rect(0, 0, width, height)}
                                            : render::HoleRegions(core.coverage, std::max(radius, kHoleScoreMarginPx));
  const int num_regions = static_cast<int>(regions.size());
  std::vector<std::vector<PartialPixel>> partial(regions.size());
  for (int i = 0; i < num_regions; ++i) partial[i] = PartialPixelsIn(regions[i], core.coverage, composite);
  // Holes drawn again from the views the mesh did not blend there (hole_views.h) become known.
  cv::Mat known = core.coverage;
  stats_.other_view_pixels = 0;
  if (stats_.hole_pixels > 0 && options_.holes_from_other_views) {
    known = core.coverage.clone();
    // The preview leaves holes under 2 radius + 1 px across to its 7x7 fill (the paper's rule).
    const int small_radius = quality == RenderQuality::kPreview ? radius : 0;
    stats_.other_view_pixels = render::CoverHolesFromOtherViews(scene_,
                                                                camera,
                                                                cam_from_world,
                                                                slots_,
                                                                quality,
                                                                options_.covered_alpha,
                                                                options_.texture_stretch,
                                                                small_radius,
                                                                &known,
                                                                &composite)
                                   .covered;
  }
  std::vector<HoleCounts> counts(regions.size());
  cv::parallel_for_(cv::Range(0, num_regions + 1), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      if (i == num_regions) {
        core.holes =
            MeasureCoverage(core.coverage, inpaint ? render::HoleRegions(core.coverage, kHoleScoreMarginPx) : regions);
      } else {
        counts[i] = FillHolesIn(regions[i], inpaint, options_, scene_.soft_z(), known, partial[i], &composite);
      }
    }
  });
  for (const HoleCounts& c : counts) {
    stats_.small_hole_pixels += c.small;
    stats_.propagated_pixels += c.propagated;
    stats_.inpainted_pixels += c.inpainted;
  }
  stats_.holes_ms += MsSince(start);

  start = StageClock::now();
  render::ApplyColorEffects(effects, camera, cam_from_world, composite.depth, &composite.colour);
  stats_.effects_ms += MsSince(start);

  std::vector<std::pair<double, ViewId>> by_weight;
  for (const render::FrameView& fv : frame_views) by_weight.emplace_back(-fv.weight_sum, scene_.views()[fv.view].id);
  std::sort(by_weight.begin(), by_weight.end());
  for (const auto& [weight, id] : by_weight) core.sources.push_back(id);
  core.colour = composite.colour;
  core.depth = composite.depth;
  if (!composite.double_image.empty()) core.double_image = composite.double_image.clone();
  return core;
}

StatusOr<FrameRender> CpuSceneRenderer::Render(const VirtualCamera& camera) {
  PX_RETURN_IF_ERROR(camera.Validate());
  PX_RETURN_IF_ERROR(CheckCamera(camera.camera, camera.cam_from_world));
  const StageClock::time_point start = StageClock::now();
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
    const StageClock::time_point dof_start = StageClock::now();
    const render::DepthOfFieldReport dof = render::ApplyPreviewDepthOfField(
        camera.aperture_m, camera.focus_depth_m, camera.camera.fx, core.depth, &core.colour);
    stats_.silhouette_pixels = dof.silhouette_pixels;
    stats_.effects_ms += MsSince(dof_start);
  }
  frame.bgr = ToBgr8(core.colour);
  frame.depth_m = core.depth;
  frame.coverage = core.coverage;
  frame.holes = core.holes;
  frame.sources = std::move(core.sources);
  frame.double_image = std::move(core.double_image);
  stats_.total_ms = MsSince(start);
  Logger("render")->debug(
      "cpu {} frame {}x{}: {} views, {} segments; weights {:.1f} ms, setup {:.1f} ms, composite {:.1f} ms, "
      "holes {:.1f} ms ({:.2f}%), effects {:.1f} ms; {:.1f} ms in all",
      RenderQualityName(options_.quality),
      camera.camera.width,
      camera.camera.height,
      stats_.views_drawn,
      stats_.segments_drawn,
      stats_.weights_ms,
      stats_.setup_ms,
      stats_.composite_ms,
      stats_.holes_ms,
      100 * frame.holes.hole_ratio,
      stats_.effects_ms,
      stats_.total_ms);
  return frame;
}

StatusOr<CoverageReport> CpuSceneRenderer::Coverage(const CameraModel& camera, const Rigid3& cam_from_world) {
  PX_RETURN_IF_ERROR(CheckCamera(camera, cam_from_world));
  const bool coarse = coarse_scene_ != nullptr && std::max(camera.fx, camera.fy) <= kCoarseScale * min_source_focal_px_;
  const render::LayeredScene& scene = coarse ? *coarse_scene_ : scene_;
  // This call's own slots and frame views (not the Render() members): calls may run side by side.
  std::vector<render::ViewSlots> slots;
  // The paper's barycentric weights, whatever viewing_weight_exponent says: the direction stage's
  // hole measure does not depend on how the blend shares a pixel among its views.
  scene.mesh().ComputeWeights(camera, cam_from_world, &slots);
  std::vector<render::FrameView> frame_views;
  render::SetUpFrame(scene, camera, cam_from_world, slots, options_.texture_stretch, false, &frame_views);
  render::FrameComposite composite;
  render::CompositePreview(scene, frame_views, slots, camera.width, camera.height, false, &composite);
  return MeasureCoverage(composite.alpha >= options_.covered_alpha);
}

}  // namespace px
