#include "pipeline/depth/depth_stage.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include <opencv2/imgproc.hpp>

#include "pipeline/core/log.h"
#include "pipeline/depth/cost_volume.h"
#include "pipeline/depth/depth_cleanup.h"
#include "pipeline/depth/plane_homography.h"
#include "pipeline/depth/segment_planes.h"
#include "pipeline/depth/select_planes.h"
#include "pipeline/depth/superpixels.h"
#include "pipeline/depth/zncc_cost.h"
#include "pipeline/depth/working_view.h"

namespace px {
namespace {

using Clock = std::chrono::steady_clock;
using depth::WorkingView;

double MsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

Status CheckInputs(const std::vector<View>& views, const DepthOptions& options) {
  PX_RETURN_IF_ERROR(options.Validate());
  if (!options.HasDepthRange()) {
    std::ostringstream error;
    error << "depth options: depth range [" << options.min_depth_m << ", " << options.max_depth_m
          << "] m is not set (fill it from the rig with WithDefaultDepthRange)";
    return InvalidArgumentError(error.str());
  }
  return depth::CheckViews(views, options.working_scale, options.matching.window_radius_px);
}

// Largest and smallest distance between the reference camera centre and its neighbours'.
void BaselineRange(const std::vector<View>& views, int reference, const std::vector<int>& neighbours,
                   double* nearest_m, double* farthest_m) {
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
  DepthMap map;
};

ReferenceDepth MatchReference(const std::vector<View>& views, const std::vector<WorkingView>& working, int reference,
                              const DepthOptions& options) {
  const MatchingOptions& m = options.matching;
  const WorkingView& ref = working[reference];
  const std::vector<int> neighbour_ids = depth::NearestNeighbourViews(views, reference, m.num_neighbors);
  std::vector<const WorkingView*> neighbours;
  for (int k : neighbour_ids) neighbours.push_back(&working[k]);
  double nearest_m = 0, farthest_m = 0;
  BaselineRange(views, reference, neighbour_ids, &nearest_m, &farthest_m);
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
  const double step_px = ref.camera.fx * nearest_m * planes.step_inverse_m;
  const int fit_half_width = 2 * step_px <= 0.3 ? 2 : 1;
  depth::PlaneSelection selection = depth::SelectPlanes(volume.slices, fit_half_width);
  selection.confidence.setTo(0, volume.sampled == 0);
  const cv::Size size = ref.gray.size();
  cv::Mat pixel_inverse_depth(size, CV_32F);
  for (int y = 0; y < size.height; ++y) {
    const float* p = selection.plane.ptr<float>(y);
    float* u = pixel_inverse_depth.ptr<float>(y);
    for (int x = 0; x < size.width; ++x) u[x] = static_cast<float>(planes.InverseDepth(p[x]));
  }
  // Segments and a plane each.
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
  const auto plane_cost = [&](int s, const depth::InversePlane& plane) {
    double sum = 0;
    for (int index : segment_pixels[s]) {
      const int x = index % size.width, y = index / size.width;
      const double p = planes.PlaneOf(plane.At(x, y));
      if (p < 0 || p > planes.count - 1) {
        sum += depth::kNoDataCost;
        continue;
      }
      const int p0 = std::min(static_cast<int>(p), planes.count - 2);
      const double t = p - p0;
      sum += (1 - t) * volume.slices[p0].at<float>(y, x) + t * volume.slices[p0 + 1].at<float>(y, x);
    }
    return sum / std::max<size_t>(segment_pixels[s].size(), 1);
  };
  depth::AssignUnfittedSegments(segments, plane_cost, {}, so.propagation_cost_margin, &segment_planes);
  volume.slices.clear();
  cv::Mat inverse_depth(size, CV_32F);
  for (int y = 0; y < size.height; ++y) {
    const int* l = segments.labels.ptr<int>(y);
    float* u = inverse_depth.ptr<float>(y);
    for (int x = 0; x < size.width; ++x) {
      const depth::SegmentPlane& sp = segment_planes[l[x]];
      u[x] = sp.source == depth::PlaneSource::kNone ? pixel_inverse_depth.at<float>(y, x)
                                                    : static_cast<float>(sp.plane.At(x, y));
    }
  }
  const View& view = views[reference];
  ReferenceDepth result;
  result.map.id = view.id;
  cv::Mat full_inverse;
  if (size == view.image.size()) {
    full_inverse = inverse_depth;
    result.map.confidence = selection.confidence;
  } else {
    depth::UpsampleJointBilateral(inverse_depth, selection.confidence, ref.bgr, view.image, &full_inverse,
                                  &result.map.confidence);
  }
  const auto near_inverse = static_cast<float>(1.0 / options.min_depth_m);
  const auto far_inverse = static_cast<float>(1.0 / options.max_depth_m);
  result.map.depth_m.create(full_inverse.size(), CV_32F);
  for (int y = 0; y < full_inverse.rows; ++y) {
    const float* u = full_inverse.ptr<float>(y);
    float* z = result.map.depth_m.ptr<float>(y);
    for (int x = 0; x < full_inverse.cols; ++x) z[x] = 1.0f / std::clamp(u[x], far_inverse, near_inverse);
  }
  return result;
}

}  // namespace

StatusOr<DepthStageResult> ComputeLayeredDepthForViews(const std::vector<View>& views,
                                                       const std::vector<int>& reference_indices,
                                                       const DepthOptions& options,
                                                       const DepthProgressCallback& progress) {
  const Clock::time_point start = Clock::now();
  PX_RETURN_IF_ERROR(CheckInputs(views, options));
  for (int index : reference_indices) {
    if (index < 0 || index >= static_cast<int>(views.size())) {
      return OutOfRangeError("reference view index " + std::to_string(index) + " is outside [0, " +
                             std::to_string(views.size()) + ")");
    }
  }
  const depth::ScopedNumThreads threads(options.num_threads);
  std::vector<WorkingView> working;
  working.reserve(views.size());
  for (const View& view : views) working.push_back(depth::MakeWorkingView(view, options.working_scale));
  DepthStageResult result;
  for (size_t i = 0; i < reference_indices.size(); ++i) {
    if (progress && !progress(static_cast<double>(i) / reference_indices.size())) {
      return CancelledError("depth cancelled after " + std::to_string(i) + " of " +
                            std::to_string(reference_indices.size()) + " views");
    }
    ReferenceDepth reference = MatchReference(views, working, reference_indices[i], options);
    result.maps.push_back(reference.map);
  }
  if (progress) progress(1.0);
  Logger("depth")->info("{} depth maps in {:.0f} ms", result.maps.size(), MsSince(start));
  return result;
}

StatusOr<DepthStageResult> ComputeLayeredDepth(const std::vector<View>& views, const DepthOptions& options,
                                               const DepthProgressCallback& progress) {
  std::vector<int> all(views.size());
  for (int i = 0; i < static_cast<int>(views.size()); ++i) all[i] = i;
  return ComputeLayeredDepthForViews(views, all, options, progress);
}

StatusOr<std::vector<DepthMap>> ComputeDepth(const std::vector<View>& views, const DepthOptions& options,
                                             const DepthProgressCallback& progress) {
  PX_ASSIGN_OR_RETURN(DepthStageResult result, ComputeLayeredDepth(views, options, progress));
  return std::move(result.maps);
}

}  // namespace px
