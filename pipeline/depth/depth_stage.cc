#include "pipeline/depth/depth_stage.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "pipeline/core/log.h"
#include "pipeline/core/order_statistics.h"
#include "pipeline/core/stage_clock.h"
#include "pipeline/depth/consistency.h"
#include "pipeline/depth/coplanar_groups.h"
#include "pipeline/depth/cost_volume.h"
#include "pipeline/depth/depth_mode.h"
#include "pipeline/depth/edge_labels.h"
#include "pipeline/depth/fill_unconfirmed.h"
#include "pipeline/depth/free_space.h"
#include "pipeline/depth/group_depth.h"
#include "pipeline/depth/neighbour_views.h"
#include "pipeline/depth/pixel_depth_near_planes.h"
#include "pipeline/depth/plane_homography.h"
#include "pipeline/depth/refine_segment_planes.h"
#include "pipeline/depth/segment_match_cost.h"
#include "pipeline/depth/segment_planes.h"
#include "pipeline/depth/select_planes.h"
#include "pipeline/depth/semi_global.h"
#include "pipeline/depth/sub_plane.h"
#include "pipeline/depth/superpixels.h"
#include "pipeline/depth/two_layer.h"
#include "pipeline/depth/volume_plane_cost.h"
#include "pipeline/depth/weak_regions.h"
#include "pipeline/depth/working_view.h"
#include "pipeline/depth/zncc_cost.h"

namespace px {
namespace {

using depth::WorkingView;

Status CheckInputs(const std::vector<View>& views, const DepthOptions& options) {
  PX_RETURN_IF_ERROR(options.Validate());
  if (!options.HasDepthRange()) {
    std::ostringstream error;
    error << "depth options: depth range [" << options.min_depth_m << ", " << options.max_depth_m
          << "] m is not set (fill it from the rig with WithDefaultDepthRange)";
    return InvalidArgumentError(error.str());
  }
  return depth::CheckViews(views,
                           depth::MatchingScale(views, options.working_scale, options.min_working_width_px),
                           options.matching.window_radius_px);
}

// Largest and smallest distance between the reference camera centre and its neighbours'.
void BaselineRange(const std::vector<View>& views,
                   int reference,
                   const std::vector<int>& neighbours,
                   double* nearest_m,
                   double* farthest_m) {
  const Eigen::Vector3d centre = CameraCentre(views[reference].cam_from_world);
  *nearest_m = 1e300;
  *farthest_m = 0;
  for (int k : neighbours) {
    const double d = (CameraCentre(views[k].cam_from_world) - centre).norm();
    *nearest_m = std::min(*nearest_m, d);
    *farthest_m = std::max(*farthest_m, d);
  }
}

struct ReferenceDepth {
  LayeredDepthView layered;
  ViewDepthReport report;
  std::vector<int> neighbours;
  // What the layered view is built from (BuildLayers), kept so that it can be rebuilt once the
  // other views' depth is known (the free-space check).
  depth::SegmentImage segment_image;
  cv::Mat pixel_confidence;     // CV_32F at view resolution
  cv::Mat pixel_inverse_depth;  // CV_32F, 0 where the plane is kept; empty: planes everywhere
  double nearest_m = 0;         // the nearest neighbour's baseline
};

struct StageTimes {
  double matching_ms = 0, segments_ms = 0, layers_ms = 0;
};

// Neighbour views of `reference` (neighbour_views.h), leaving out the `excluded` ones unless
// that leaves none.
std::vector<int> UsableNeighbours(const std::vector<View>& views,
                                  int reference,
                                  const std::vector<char>& excluded,
                                  const MatchingOptions& m) {
  const std::vector<int> all = depth::NearestNeighbourViews(views, reference, static_cast<int>(views.size()));
  std::vector<int> usable;
  for (int k : all) {
    if (!excluded[k]) usable.push_back(k);
  }
  return depth::ChooseNeighbourViews(
      views, reference, usable.empty() ? all : usable, m.num_neighbors, m.spread_neighbors);
}

// 255 where the grey window of radius r has at least min_stddev of texture.
cv::Mat TexturedPixels(const cv::Mat& gray, int radius_px, double min_stddev) {
  cv::Mat mean, mean_sq;
  const cv::Size window(2 * radius_px + 1, 2 * radius_px + 1);
  cv::boxFilter(gray, mean, CV_32F, window, cv::Point(-1, -1), true, cv::BORDER_REFLECT);
  cv::boxFilter(gray.mul(gray), mean_sq, CV_32F, window, cv::Point(-1, -1), true, cv::BORDER_REFLECT);
  cv::Mat variance = mean_sq - mean.mul(mean);
  return variance >= min_stddev * min_stddev + 1e-12;
}

// Saturated (>= 250 in every channel) and dark (grey < 8) fractions of an image.
void ExposureFractions(const cv::Mat& bgr, double* saturated, double* dark) {
  cv::Mat gray;
  cv::cvtColor(bgr, gray, cv::COLOR_BGR2GRAY);
  std::vector<cv::Mat> channels;
  cv::split(bgr, channels);
  cv::Mat all_high = (channels[0] >= 250) & (channels[1] >= 250) & (channels[2] >= 250);
  const double total = static_cast<double>(bgr.total());
  *saturated = cv::countNonZero(all_high) / total;
  *dark = cv::countNonZero(gray < 8) / total;
}

// A plane in working-scale pixels as a plane in view pixels: x' + 0.5 = (x + 0.5) * factor.
depth::InversePlane ToViewPixels(const depth::InversePlane& plane, double factor) {
  depth::InversePlane full;
  full.a = plane.a * factor;
  full.b = plane.b * factor;
  full.c = plane.c + (plane.a + plane.b) * 0.5 * (factor - 1);
  return full;
}

// Per segment, the fraction of its pixels the neighbour views did not sample over the far planes
// (`sampled`: CV_8U, 0 there; CostVolume::sampled).
std::vector<float> UnseenFractions(const std::vector<std::vector<int>>& segment_pixels, const cv::Mat& sampled) {
  std::vector<float> unseen(segment_pixels.size(), 0.0f);
  for (size_t s = 0; s < segment_pixels.size(); ++s) {
    int count = 0;
    for (int index : segment_pixels[s]) count += sampled.at<uint8_t>(index / sampled.cols, index % sampled.cols) == 0;
    unseen[s] = static_cast<float>(count) / static_cast<float>(std::max<size_t>(segment_pixels[s].size(), 1));
  }
  return unseen;
}

// Segment-level PatchMatch (refine_segment_planes.h): every segment against the cost volume,
// then the steep ones against the exact slanted cost, within slanted_max_change_px of their plane.
// `inverse_per_px` converts disparity against the nearest neighbour (working scale) to inverse depth.
void RefineSegmentPlanes(const WorkingView& ref,
                         const std::vector<const WorkingView*>& neighbours,
                         const depth::Superpixels& segments,
                         const depth::VolumePlaneCost& volume_cost,
                         const cv::Mat& pixel_inverse_depth,
                         double inverse_per_px,
                         const DepthOptions& options,
                         std::vector<depth::SegmentPlane>* planes) {
  const SegmentOptions& so = options.segments;
  depth::PlaneRefinementOptions refine;
  refine.iterations = so.refine_iterations;
  refine.random_trials = so.refine_random_trials;
  refine.offset_inverse_m = so.refine_offset_px * inverse_per_px;
  refine.slope_inverse_m_per_px = so.refine_slope_px * inverse_per_px;
  refine.seed = so.random_seed;
  depth::RefineSegmentPlanes(segments, std::cref(volume_cost), refine, planes);
  if (so.slanted_min_slope_px <= 0) return;
  refine.active.assign(segments.count, 0);
  const double min_slope = so.slanted_min_slope_px * inverse_per_px;
  bool any = false;
  for (int s = 0; s < segments.count; ++s) {
    refine.active[s] = std::hypot((*planes)[s].plane.a, (*planes)[s].plane.b) > min_slope ? 1 : 0;
    any = any || refine.active[s];
  }
  if (!any) return;
  refine.max_change_inverse_m = so.slanted_max_change_px * inverse_per_px;
  constexpr double kRingTolerancePx = 1.0;  // ring pixels whose own depth is this near the plane
  const depth::SegmentMatchCost slanted(ref,
                                        neighbours,
                                        segments,
                                        pixel_inverse_depth,
                                        *planes,
                                        so.slanted_ring_px,
                                        kRingTolerancePx * inverse_per_px,
                                        options.matching.min_texture_stddev);
  depth::RefineSegmentPlanes(segments, std::cref(slanted), refine, planes);
}

// The layered view of `reference`'s segment image (BuildTwoLayerView), with the matcher's
// per-pixel depth kept near the planes and depth clamped to the swept range.
LayeredDepthView BuildLayers(const View& view, const ReferenceDepth& reference, const DepthOptions& options) {
  const SegmentOptions& so = options.segments;
  depth::TwoLayerOptions layer_options;
  layer_options.edge_inverse_depth_m = so.edge_disparity_px / (view.camera.fx * reference.nearest_m);
  layer_options.band_radius_px = so.band_radius_px;
  layer_options.min_inverse_depth_m = 0.5 / options.max_depth_m;
  LayeredDepthView layered = depth::BuildTwoLayerView(
      view.id, view.camera, view.image, reference.segment_image, reference.pixel_confidence, layer_options);
  if (!reference.pixel_inverse_depth.empty()) {
    depth::KeepPixelDepthNearPlanes(
        reference.pixel_inverse_depth, so.pixel_depth_tolerance_px / (view.camera.fx * reference.nearest_m), &layered);
  }
  // Depth within the swept range (planes may extrapolate past it at a segment's far corner).
  cv::max(layered.depth_m, options.min_depth_m, layered.depth_m);
  cv::min(layered.depth_m, options.max_depth_m, layered.depth_m);
  return layered;
}

ReferenceDepth MatchReference(const std::vector<View>& views,
                              const std::vector<WorkingView>& working,
                              const std::vector<WorkingView>& full_resolution,
                              int reference,
                              const std::vector<char>& excluded,
                              const DepthOptions& options,
                              StageTimes* times) {
  StageClock::time_point start = StageClock::now();
  const MatchingOptions& m = options.matching;
  const WorkingView& ref = working[reference];
  const View& view = views[reference];
  ReferenceDepth result;
  result.neighbours = UsableNeighbours(views, reference, excluded, m);
  std::vector<const WorkingView*> neighbours;
  for (int k : result.neighbours) neighbours.push_back(&working[k]);
  double nearest_m = 0, farthest_m = 0;
  BaselineRange(views, reference, result.neighbours, &nearest_m, &farthest_m);
  const double inverse_span = 1.0 / options.min_depth_m - 1.0 / options.max_depth_m;
  int num_planes = m.num_planes;
  if (num_planes == 0) {
    const double span_px = ref.camera.fx * farthest_m * inverse_span;
    num_planes = std::clamp(static_cast<int>(std::ceil(span_px / m.plane_step_px)) + 1, 2, m.max_planes);
  }
  const depth::InverseDepthPlanes planes =
      depth::MakeInverseDepthPlanes(options.min_depth_m, options.max_depth_m, num_planes);
  depth::CostVolumeOptions volume_options;
  volume_options.window_radius_px = m.window_radius_px;
  volume_options.min_texture_stddev = m.min_texture_stddev;
  volume_options.filter_radius_px = m.cost_filter_radius_px;
  volume_options.filter_eps = m.cost_filter_eps;
  depth::CostVolume volume = depth::BuildCostVolume(ref, neighbours, planes, volume_options);
  // How well the view matches its neighbours at all: the median over textured pixels of the best
  // cost before aggregation, so that the check's threshold holds whatever the filter radius.
  const cv::Size size = ref.gray.size();
  const cv::Mat textured = TexturedPixels(ref.gray, m.window_radius_px, m.min_texture_stddev);
  {
    std::vector<float> costs, typical;
    costs.reserve(size.area());
    typical.reserve(size.area());
    for (int y = 0; y < size.height; ++y) {
      const float* c = volume.best_unfiltered_cost.ptr<float>(y);
      const float* u = volume.typical_unfiltered_cost.ptr<float>(y);
      const uint8_t* t = textured.ptr<uint8_t>(y);
      for (int x = 0; x < size.width; ++x) {
        if (!t[x]) continue;
        costs.push_back(c[x]);
        if (u[x] < depth::kNoDataCost) typical.push_back(u[x]);
      }
    }
    result.report.median_match_cost = costs.empty() ? depth::kNeutralCost : Median(std::move(costs));
    result.report.median_typical_cost = typical.empty() ? depth::kNeutralCost : Median(std::move(typical));
    Logger("depth")->debug("view {}: median matching cost {:.3f}, {:.3f} at other depths",
                           view.id.value,
                           result.report.median_match_cost,
                           result.report.median_typical_cost);
  }
  result.report.textureless_fraction = 1.0 - cv::countNonZero(textured) / static_cast<double>(size.area());
  // With semi-global aggregation the winner comes from the aggregate and its sub-plane position
  // from the raw costs near it; the aggregate then replaces the raw costs (two volumes at most).
  std::vector<cv::Mat> aggregated;
  if (m.sgm_paths > 0) {
    depth::SemiGlobalOptions sgm;
    sgm.num_paths = m.sgm_paths;
    sgm.step_penalty = static_cast<float>(m.sgm_step_penalty);
    sgm.jump_penalty = static_cast<float>(m.sgm_jump_penalty);
    aggregated = depth::AggregateSemiGlobal(ref.gray, sgm, volume.slices);
  }
  const double step_px = ref.camera.fx * nearest_m * planes.step_inverse_m;
  const int fit_half_width = 2 * step_px <= 0.3 ? 2 : 1;
  depth::PlaneSelection selection =
      depth::SelectPlanes(aggregated.empty() ? volume.slices : aggregated, fit_half_width);
  if (!aggregated.empty()) {
    depth::RefineAroundWinners(volume.slices, /*search_planes=*/2, fit_half_width >= 2, &selection.plane);
    volume.slices = std::move(aggregated);
  }
  selection.confidence.setTo(0, volume.sampled == 0);
  cv::Mat pixel_inverse_depth(size, CV_32F);
  for (int y = 0; y < size.height; ++y) {
    const float* p = selection.plane.ptr<float>(y);
    float* u = pixel_inverse_depth.ptr<float>(y);
    for (int x = 0; x < size.width; ++x) u[x] = static_cast<float>(planes.InverseDepth(p[x]));
  }
  times->matching_ms += MsSince(start);

  // Segments and a plane each.
  start = StageClock::now();
  const SegmentOptions& so = options.segments;
  const depth::Superpixels segments =
      depth::Oversegment(ref.bgr, so.region_size_px, static_cast<float>(so.compactness), so.iterations);
  depth::PlaneFitOptions fit;
  fit.min_weight = static_cast<float>(so.min_confidence);
  fit.inlier_tolerance = so.inlier_px / (ref.camera.fx * nearest_m);
  fit.ransac_iterations = so.ransac_iterations;
  fit.min_support = so.min_support;
  fit.seed = so.random_seed;
  std::vector<depth::SegmentPlane> segment_planes =
      depth::FitSegmentPlanes(segments, pixel_inverse_depth, selection.confidence, fit);
  const std::vector<std::vector<int>> segment_pixels = depth::SegmentPixels(segments);
  depth::CoplanarGroups groups;
  if (so.coplanar_keep_fraction > 0) {
    depth::CoplanarGroupOptions coplanar;
    coplanar.min_weight = fit.min_weight;
    coplanar.tolerance = so.coplanar_tolerance_px / (ref.camera.fx * nearest_m);
    coplanar.min_support = so.min_support;
    coplanar.keep_fraction = so.coplanar_keep_fraction;
    groups = depth::MergeCoplanarSegments(
        segments, segment_pixels, pixel_inverse_depth, selection.confidence, coplanar, &segment_planes);
    Logger("depth")->debug("view {}: {} of {} segments in {} coplanar groups",
                           view.id.value,
                           groups.grouped_segments,
                           segments.count,
                           groups.groups);
  }
  const depth::VolumePlaneCost volume_cost(volume.slices, planes, segment_pixels);
  depth::AssignUnfittedSegments(segments,
                                std::cref(volume_cost),
                                {},
                                UnseenFractions(segment_pixels, volume.sampled),
                                so.propagation_cost_margin,
                                &segment_planes);
  if (so.weak_region_colour_lab > 0) {
    depth::WeakRegionOptions weak;
    weak.same_colour_lab = static_cast<float>(so.weak_region_colour_lab);
    weak.cost_margin = so.weak_region_cost_margin;
    const depth::WeakRegionStats stats =
        depth::UnifyWeakRegions(segments, std::cref(volume_cost), weak, &segment_planes);
    Logger("depth")->debug(
        "view {}: {} weak regions, {} segments changed", view.id.value, stats.regions, stats.changed_segments);
  }
  if (so.refine_iterations > 0) {
    RefineSegmentPlanes(ref,
                        neighbours,
                        segments,
                        volume_cost,
                        pixel_inverse_depth,
                        1.0 / (ref.camera.fx * nearest_m),
                        options,
                        &segment_planes);
  }
  volume.slices.clear();
  times->segments_ms += MsSince(start);

  // The two-layer view at view resolution.
  start = StageClock::now();
  const bool scaled = size != view.image.size();
  const double factor = scaled ? ref.camera.fx / view.camera.fx : 1.0;
  depth::SegmentImage image;
  image.labels = scaled ? depth::UpsampleLabels(segments, view.image, factor) : segments.labels;
  image.planes.resize(segments.count);
  image.confidence.resize(segments.count);
  for (int s = 0; s < segments.count; ++s) {
    depth::InversePlane plane = segment_planes[s].plane;
    if (segment_planes[s].source == depth::PlaneSource::kNone) {
      // Nothing to go on: level at the per-pixel estimate at the segment's centre.
      const cv::Point2f c = segments.centroids[s];
      plane = depth::InversePlane();
      plane.c = pixel_inverse_depth.at<float>(std::clamp(cvRound(c.y), 0, size.height - 1),
                                              std::clamp(cvRound(c.x), 0, size.width - 1));
    }
    image.planes[s] = ToViewPixels(plane, factor);
    image.confidence[s] = segment_planes[s].confidence;
  }
  cv::Mat confidence;
  if (scaled) {
    cv::resize(selection.confidence, confidence, view.image.size(), 0, 0, cv::INTER_LINEAR);
  } else {
    confidence = selection.confidence;
  }
  if (so.group_depth_search_px > 0 && groups.groups > 0) {
    std::vector<const WorkingView*> full_resolution_neighbours;
    for (int k : result.neighbours) full_resolution_neighbours.push_back(&full_resolution[k]);
    depth::GroupDepthOptions group_depth;
    group_depth.pixel_inverse_depth = 1.0 / (view.camera.fx * nearest_m);
    group_depth.search_px = so.group_depth_search_px;
    group_depth.step_px = group_depth.search_px / 5;
    group_depth.min_texture_stddev = options.matching.min_texture_stddev;
    const depth::GroupDepthStats stats = depth::RefineGroupDepths(
        full_resolution[reference], full_resolution_neighbours, groups.group_of, group_depth, &image);
    Logger("depth")->debug("view {}: {} of {} coplanar groups moved, mean {:.3f} px",
                           view.id.value,
                           stats.moved,
                           stats.groups,
                           stats.mean_abs_shift_px);
  }
  if (so.edge_label_radius_px > 0) {
    std::vector<const View*> full_neighbours;
    for (int k : result.neighbours) full_neighbours.push_back(&views[k]);
    depth::EdgeLabelOptions edge;
    edge.edge_inverse_depth_m = so.edge_disparity_px / (view.camera.fx * nearest_m);
    edge.radius_px = so.edge_label_radius_px;
    edge.smoothness = so.edge_label_smoothness;
    edge.visibility = so.edge_label_visibility;
    const depth::EdgeLabelStats stats = depth::RefineDepthEdgeLabels(view, full_neighbours, edge, &image);
    Logger("depth")->debug("view {}: {} of {} pixels near depth edges took another segment ({} segments emptied)",
                           view.id.value,
                           stats.changed,
                           stats.reconsidered,
                           stats.dropped_segments);
  }
  result.segment_image = std::move(image);
  result.pixel_confidence = confidence;
  result.nearest_m = nearest_m;
  // Matched below view resolution, the per-pixel depth is no finer than the plane and blurs
  // across depth edges when upsampled (measured worse near edges on the simulated Pop9).
  if (so.pixel_depth_tolerance_px > 0 && !scaled) {
    // Unconfident pixels (weak texture) are left out: inverse depth 0 keeps the plane.
    pixel_inverse_depth.setTo(0, selection.confidence < so.pixel_depth_min_confidence);
    result.pixel_inverse_depth = pixel_inverse_depth;
  }
  result.layered = BuildLayers(view, result, options);
  if (!options.free_space_replane) {  // only the free-space check rebuilds the layers
    result.segment_image = depth::SegmentImage();
    result.pixel_confidence.release();
    result.pixel_inverse_depth.release();
  }
  result.report.id = view.id;
  result.report.computed = true;
  result.report.num_segments = static_cast<int>(result.segment_image.planes.size());
  result.report.num_boundary_pixels = depth::CountBoundaryPixels(result.layered);
  ExposureFractions(view.image, &result.report.saturated_fraction, &result.report.dark_fraction);
  times->layers_ms += MsSince(start);
  return result;
}

// The other computed views of `i` that its depth is checked against: up to four of its
// neighbours, those whose depth is in `depth_m`.
std::vector<int> CheckingViews(const ReferenceDepth& reference, const std::vector<cv::Mat>& depth_m) {
  constexpr int kCheckedNeighbours = 4;
  std::vector<int> others;
  for (int k : reference.neighbours) {
    if (!depth_m[k].empty() && static_cast<int>(others.size()) < kCheckedNeighbours) others.push_back(k);
  }
  return others;
}

// Depth maps of the views whose depth can be trusted to check the others by (not disagreeing).
std::vector<cv::Mat> CheckingDepthMaps(const std::vector<View>& views,
                                       const std::vector<int>& reference_indices,
                                       const std::vector<ReferenceDepth>& references) {
  std::vector<cv::Mat> depth_m(views.size());
  for (size_t i = 0; i < reference_indices.size(); ++i) {
    // A copy: changing one view's depth must not change what the views after it are checked against.
    if (!references[i].report.disagrees) depth_m[reference_indices[i]] = references[i].layered.depth_m.clone();
  }
  return depth_m;
}

// Weak segments that the other views see through take an adjacent segment's plane
// (free_space.h), and their views' layers are rebuilt.
void ApplyFreeSpace(const std::vector<View>& views,
                    const std::vector<int>& reference_indices,
                    const DepthOptions& options,
                    std::vector<ReferenceDepth>* references) {
  const std::vector<cv::Mat> depth_m = CheckingDepthMaps(views, reference_indices, *references);
  depth::FreeSpaceOptions free_space;
  free_space.confirm_px = options.consistency_tolerance_px;
  free_space.max_confidence = options.free_space_max_confidence;
  for (size_t i = 0; i < reference_indices.size(); ++i) {
    ReferenceDepth& reference = (*references)[i];
    if (reference.report.disagrees) continue;
    const std::vector<int> others = CheckingViews(reference, depth_m);
    if (others.empty()) continue;
    const int index = reference_indices[i];
    const depth::FreeSpaceStats stats =
        depth::ReplaneSeenThroughSegments(views, depth_m, index, others, free_space, &reference.segment_image);
    Logger("depth")->debug("view {}: {} weak segments seen through by the other views, {} re-planed",
                           views[index].id.value,
                           stats.contradicted,
                           stats.replaned);
    if (stats.replaned == 0) continue;
    reference.layered = BuildLayers(views[index], reference, options);
    reference.report.num_boundary_pixels = depth::CountBoundaryPixels(reference.layered);
  }
}

// Lowers the confidence of pixels (and segments) that no other computed view confirms.
void ApplyConsistency(const std::vector<View>& views,
                      const std::vector<int>& reference_indices,
                      const DepthOptions& options,
                      std::vector<ReferenceDepth>* references) {
  const std::vector<cv::Mat> depth_m = CheckingDepthMaps(views, reference_indices, *references);
  for (size_t i = 0; i < reference_indices.size(); ++i) {
    ReferenceDepth& reference = (*references)[i];
    const std::vector<int> others = CheckingViews(reference, depth_m);
    if (others.empty() || reference.report.disagrees) continue;
    const cv::Mat consistent =
        depth::ConsistentPixels(views, depth_m, reference_indices[i], others, options.consistency_tolerance_px);
    LayeredDepthView& layered = reference.layered;
    layered.confidence.setTo(0, layered.confidence < 0);  // keeps the mask ops below well-defined
    cv::Mat halved = layered.confidence * 0.5;
    halved.copyTo(layered.confidence, consistent == 0);
    if (options.fill_unconfirmed) depth::FillUnconfirmedFromBackground(consistent, &layered.depth_m);
    reference.report.consistent_fraction = cv::countNonZero(consistent) / static_cast<double>(consistent.total());
    // A segment keeps confidence in proportion to how much of it is confirmed.
    std::vector<int> total(layered.segments.size(), 0), confirmed(layered.segments.size(), 0);
    for (int y = 0; y < consistent.rows; ++y) {
      const int32_t* s = layered.layers[0].segment.ptr<int32_t>(y);
      const uint8_t* c = consistent.ptr<uint8_t>(y);
      for (int x = 0; x < consistent.cols; ++x) {
        if (s[x] < 0) continue;
        ++total[s[x]];
        confirmed[s[x]] += c[x] ? 1 : 0;
      }
    }
    for (size_t s = 0; s < layered.segments.size(); ++s) {
      if (total[s] > 0) layered.segments[s].confidence *= 0.5f + 0.5f * confirmed[s] / static_cast<float>(total[s]);
    }
  }
}

// Whether a view matches none of its neighbours: a black or saturated frame, or textured pixels
// that match nothing while the shot's other views do (its cost both over the threshold and well
// above the shot's median view). A view with (nearly) no texture cannot tell, and is not counted
// as disagreeing: its depth is merely unconfident.
bool Disagrees(const ViewDepthReport& report, double shot_median_cost, const DepthOptions& options) {
  if (report.dark_fraction > 0.9 || report.saturated_fraction > 0.9) return true;
  return report.textureless_fraction < 0.95 && report.median_match_cost > options.max_view_match_cost &&
         report.median_match_cost > options.view_match_outlier_ratio * shot_median_cost;
}

// The median of the views' matching costs, over the views that can be judged by it (textured,
// neither black nor saturated); 0 when there are none.
double ShotMedianMatchCost(const std::vector<ReferenceDepth>& references) {
  std::vector<float> costs;
  for (const ReferenceDepth& reference : references) {
    const ViewDepthReport& report = reference.report;
    if (report.dark_fraction > 0.9 || report.saturated_fraction > 0.9 || report.textureless_fraction >= 0.95) continue;
    costs.push_back(static_cast<float>(report.median_match_cost));
  }
  return costs.empty() ? 0.0 : Median(std::move(costs));
}

std::string Percent(double fraction) { return std::to_string(static_cast<int>(std::lround(100 * fraction))) + "%"; }

// Confidence summaries, the low-confidence mask and the reasons a view's depth is degraded.
void FinishReport(const DepthOptions& options, ReferenceDepth* reference) {
  ViewDepthReport& report = reference->report;
  const cv::Mat& confidence = reference->layered.confidence;
  report.confident_fraction = cv::countNonZero(confidence >= 0.5f) / static_cast<double>(confidence.total());
  report.low_confidence = confidence < 0.25f;
  if (report.disagrees) {
    std::ostringstream reason;
    reason << "matches none of its neighbours (median matching cost " << report.median_match_cost << " > "
           << options.max_view_match_cost << " and " << options.view_match_outlier_ratio
           << " times the shot's median view; " << report.median_typical_cost
           << " at other depths): another scene, a black or saturated frame?";
    report.reasons.push_back(reason.str());
  }
  if (report.textureless_fraction > 0.3)
    report.reasons.push_back(Percent(report.textureless_fraction) + " of pixels have no texture to match");
  if (report.saturated_fraction > 0.2)
    report.reasons.push_back(Percent(report.saturated_fraction) + " of pixels are saturated");
  if (report.dark_fraction > 0.5)
    report.reasons.push_back(Percent(report.dark_fraction) + " of pixels are nearly black");
  if (report.consistent_fraction > 0 && report.consistent_fraction < 0.5) {
    report.reasons.push_back("only " + Percent(report.consistent_fraction) +
                             " of pixels agree with another view's depth");
  }
  if (report.confident_fraction < 0.3)
    report.reasons.push_back("only " + Percent(report.confident_fraction) + " of pixels have confident depth");
}

// ComputeLayeredDepthForViews with the options of the shot's depth mode (ChooseDepthMode).
StatusOr<DepthStageResult> ComputeWithModeOptions(const std::vector<View>& views,
                                                  const std::vector<int>& reference_indices,
                                                  const DepthOptions& options,
                                                  const DepthProgressCallback& progress) {
  const StageClock::time_point start = StageClock::now();
  for (int index : reference_indices) {
    if (index < 0 || index >= static_cast<int>(views.size())) {
      return OutOfRangeError("reference view index " + std::to_string(index) + " is outside [0, " +
                             std::to_string(views.size()) + ")");
    }
  }
  const depth::ScopedNumThreads threads(options.num_threads);
  std::vector<WorkingView> working;
  working.reserve(views.size());
  const double scale = depth::MatchingScale(views, options.working_scale, options.min_working_width_px);
  for (const View& view : views) working.push_back(depth::MakeWorkingView(view, scale));
  // Full-resolution grey views for the coplanar groups' depth, made once for every reference.
  std::vector<WorkingView> full_resolution;
  if (options.segments.group_depth_search_px > 0) {
    full_resolution.reserve(views.size());
    for (size_t i = 0; i < views.size(); ++i) {
      full_resolution.push_back(scale < 1 ? depth::MakeWorkingView(views[i], 1.0) : working[i]);
    }
  }
  StageTimes times;
  std::vector<char> excluded(views.size(), 0);
  std::vector<ReferenceDepth> references(reference_indices.size());
  const auto match_all = [&](const std::vector<char>& redo) -> Status {
    for (size_t i = 0; i < reference_indices.size(); ++i) {
      if (!redo[i]) continue;
      if (progress && !progress(0.9 * static_cast<double>(i) / reference_indices.size())) {
        return CancelledError("depth cancelled after " + std::to_string(i) + " of " +
                              std::to_string(reference_indices.size()) + " views");
      }
      references[i] = MatchReference(views, working, full_resolution, reference_indices[i], excluded, options, &times);
    }
    return OkStatus();
  };
  PX_RETURN_IF_ERROR(match_all(std::vector<char>(reference_indices.size(), 1)));

  // Views that match none of their neighbours: reported, their depth not trusted, and (when
  // the rest of the shot does match) left out as neighbours of the others, which are redone.
  const double shot_median_cost = ShotMedianMatchCost(references);
  int num_disagreeing = 0;
  for (size_t i = 0; i < reference_indices.size(); ++i) {
    if (Disagrees(references[i].report, shot_median_cost, options)) {
      references[i].report.disagrees = true;
      ++num_disagreeing;
    }
  }
  DepthStageResult result;
  if (num_disagreeing > 0 && num_disagreeing < static_cast<int>(reference_indices.size())) {
    std::vector<char> redo(reference_indices.size(), 0);
    for (size_t i = 0; i < reference_indices.size(); ++i) {
      if (references[i].report.disagrees) excluded[reference_indices[i]] = 1;
    }
    for (size_t i = 0; i < reference_indices.size(); ++i) {
      if (references[i].report.disagrees) continue;
      for (int k : references[i].neighbours) redo[i] = redo[i] || excluded[k];
    }
    PX_RETURN_IF_ERROR(match_all(redo));
  } else if (num_disagreeing > 0) {
    result.report.warnings.push_back(
        "depth: no view matches its neighbours (all views of different scenes, or "
        "all black or saturated): depth is guesswork everywhere");
  }
  if (num_disagreeing == 0 && shot_median_cost > options.max_view_match_cost) {
    std::ostringstream warning;
    warning << "depth: every view matches its neighbours poorly (median matching cost " << shot_median_cost << " > "
            << options.max_view_match_cost << "): lenses differing in exposure, colour or vignetting, a subject "
            << "moving between exposures, or poses off; depth is trusted only where the views agree";
    result.report.warnings.push_back(warning.str());
  }
  for (size_t i = 0; i < reference_indices.size(); ++i) {
    if (Disagrees(references[i].report, shot_median_cost, options)) {
      references[i].report.disagrees = true;
      references[i].layered.confidence.setTo(0);
      for (DepthSegment& segment : references[i].layered.segments) segment.confidence = 0;
    }
  }
  StageClock::time_point consistency_start = StageClock::now();
  if (options.free_space_replane) ApplyFreeSpace(views, reference_indices, options, &references);
  for (ReferenceDepth& reference : references) {  // what the layers were built from is no longer needed
    reference.segment_image = depth::SegmentImage();
    reference.pixel_confidence.release();
    reference.pixel_inverse_depth.release();
  }
  ApplyConsistency(views, reference_indices, options, &references);
  result.report.consistency_ms = MsSince(consistency_start);

  result.report.views.resize(views.size());
  for (size_t k = 0; k < views.size(); ++k) result.report.views[k].id = views[k].id;
  double confident_sum = 0, consistent_sum = 0;
  int agreeing_views = 0;
  for (size_t i = 0; i < reference_indices.size(); ++i) {
    FinishReport(options, &references[i]);
    ViewDepthReport& report = references[i].report;
    confident_sum += report.confident_fraction;
    if (report.disagrees) {
      result.report.disagreeing_views.push_back(report.id);
    } else {
      consistent_sum += report.consistent_fraction;
      ++agreeing_views;
    }
    for (const std::string& reason : report.reasons) {
      result.report.warnings.push_back("depth: view " + std::to_string(report.id.value) + " " + reason);
    }
    result.report.views[reference_indices[i]] = report;
    result.maps.push_back(references[i].layered.ToDepthMap());
    result.layered.push_back(std::move(references[i].layered));
  }
  result.report.confident_fraction = reference_indices.empty() ? 0 : confident_sum / reference_indices.size();
  result.report.consistent_fraction = agreeing_views == 0 ? 0 : consistent_sum / agreeing_views;
  result.report.matching_ms = times.matching_ms;
  result.report.segments_ms = times.segments_ms;
  result.report.layers_ms = times.layers_ms;
  if (progress) progress(1.0);
  Logger("depth")->info(
      "{} layered depth views in {:.0f} ms (matching {:.0f}, segments {:.0f}, layers {:.0f}, "
      "consistency {:.0f}), {:.0f}% confident, {:.0f}% confirmed by another view, {} disagreeing",
      result.maps.size(),
      MsSince(start),
      times.matching_ms,
      times.segments_ms,
      times.layers_ms,
      result.report.consistency_ms,
      100 * result.report.confident_fraction,
      100 * result.report.consistent_fraction,
      result.report.disagreeing_views.size());
  for (const std::string& warning : result.report.warnings) Logger("depth")->warn("{}", warning);
  return result;
}

}  // namespace

StatusOr<DepthStageResult> ComputeLayeredDepthForViews(const std::vector<View>& views,
                                                       const std::vector<int>& reference_indices,
                                                       const DepthOptions& options,
                                                       const DepthProgressCallback& progress) {
  PX_RETURN_IF_ERROR(CheckInputs(views, options));
  const DepthModeChoice mode = ChooseDepthMode(views, options);
  Logger("depth")->info("{}", mode.reason);
  PX_ASSIGN_OR_RETURN(DepthStageResult result,
                      ComputeWithModeOptions(views, reference_indices, mode.options, progress));
  result.report.light_field = mode.light_field;
  result.report.mode = mode.reason;
  return result;
}

StatusOr<DepthStageResult> ComputeLayeredDepth(const std::vector<View>& views,
                                               const DepthOptions& options,
                                               const DepthProgressCallback& progress) {
  std::vector<int> all(views.size());
  for (int i = 0; i < static_cast<int>(views.size()); ++i) all[i] = i;
  return ComputeLayeredDepthForViews(views, all, options, progress);
}

StatusOr<std::vector<DepthMap>> ComputeDepth(const std::vector<View>& views,
                                             const DepthOptions& options,
                                             const DepthProgressCallback& progress) {
  PX_ASSIGN_OR_RETURN(DepthStageResult result, ComputeLayeredDepth(views, options, progress));
  return std::move(result.maps);
}

}  // namespace px
