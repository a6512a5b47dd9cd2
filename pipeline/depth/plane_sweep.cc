#include "pipeline/depth/plane_sweep.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <string>

#include "pipeline/core/log.h"
#include "pipeline/core/stage_clock.h"
#include "pipeline/depth/cost_volume.h"
#include "pipeline/depth/depth_cleanup.h"
#include "pipeline/depth/plane_homography.h"
#include "pipeline/depth/select_planes.h"
#include "pipeline/depth/working_view.h"

namespace px {
namespace {

using depth::MakeWorkingView;
using depth::ScopedNumThreads;
using depth::WorkingView;

Status CheckInputs(const std::vector<View>& views, const PlaneSweepOptions& options) {
  PX_RETURN_IF_ERROR(options.Validate());
  if (!options.HasDepthRange()) {
    std::ostringstream error;
    error << "plane sweep options: depth range [" << options.min_depth_m << ", " << options.max_depth_m
          << "] m is not set (fill it from the rig with WithDefaultDepthRange)";
    return InvalidArgumentError(error.str());
  }
  return depth::CheckViews(views, options.working_scale, options.window_radius_px);
}

// Distance between the reference camera centre and its nearest neighbour's.
double NearestBaselineM(const std::vector<View>& views, int reference, const std::vector<int>& neighbours) {
  const Eigen::Vector3d centre = CameraCentre(views[reference].cam_from_world);
  double nearest = std::numeric_limits<double>::max();
  for (int k : neighbours) nearest = std::min(nearest, (CameraCentre(views[k].cam_from_world) - centre).norm());
  return nearest;
}

DepthMap SweepReference(const std::vector<View>& views,
                        const std::vector<WorkingView>& working,
                        int reference,
                        const PlaneSweepOptions& options) {
  const WorkingView& ref = working[reference];
  const std::vector<int> neighbour_ids = depth::NearestNeighbourViews(views, reference, options.num_neighbors);
  std::vector<const WorkingView*> neighbours;
  for (int k : neighbour_ids) neighbours.push_back(&working[k]);
  const depth::InverseDepthPlanes sampling =
      depth::MakeInverseDepthPlanes(options.min_depth_m, options.max_depth_m, options.num_planes);
  depth::CostVolumeOptions volume_options;
  volume_options.window_radius_px = options.window_radius_px;
  volume_options.min_texture_stddev = options.min_texture_stddev;
  volume_options.filter_radius_px = options.cost_filter_radius_px;
  volume_options.filter_eps = options.cost_filter_eps;
  depth::CostVolume volume = depth::BuildCostVolume(ref, neighbours, sampling, volume_options);

  // Five-point sub-plane fits when two plane steps move the nearest neighbour's image by at most
  // 0.3 px (measured best on the HCI light field; on coarser sampling the three-point fit wins).
  const double step_px = ref.camera.fx * NearestBaselineM(views, reference, neighbour_ids) * sampling.step_inverse_m;
  const int fit_half_width = 2 * step_px <= 0.3 ? 2 : 1;
  depth::PlaneSelection selection = depth::SelectPlanes(volume.slices, fit_half_width);
  volume.slices.clear();
  selection.confidence.setTo(0, volume.sampled == 0);
  const auto fill_confidence = static_cast<float>(options.fill_confidence);
  // Speckles keep their depth but end up below the fill threshold, so the fill may replace it.
  depth::LowerSpeckleConfidence(selection.plane,
                                options.speckle_max_size_px,
                                /*max_jump_planes=*/2.0f,
                                0.5f * fill_confidence,
                                &selection.confidence);
  const cv::Size size = ref.gray.size();
  cv::Mat inverse_depth(size, CV_32F);
  for (int y = 0; y < size.height; ++y) {
    const float* p = selection.plane.ptr<float>(y);
    float* u = inverse_depth.ptr<float>(y);
    for (int x = 0; x < size.width; ++x) u[x] = static_cast<float>(sampling.InverseDepth(p[x]));
  }
  const auto near_inverse = static_cast<float>(1.0 / options.min_depth_m);
  const auto far_inverse = static_cast<float>(sampling.far_inverse_m);
  depth::FillLowConfidence(ref.bgr, selection.confidence, fill_confidence, far_inverse, near_inverse, &inverse_depth);

  const View& view = views[reference];
  DepthMap result;
  result.id = view.id;
  cv::Mat full_inverse;
  if (size == view.image.size()) {
    full_inverse = inverse_depth;
    result.confidence = selection.confidence;
  } else {
    depth::UpsampleJointBilateral(
        inverse_depth, selection.confidence, ref.bgr, view.image, &full_inverse, &result.confidence);
  }
  result.depth_m.create(full_inverse.size(), CV_32F);
  for (int y = 0; y < full_inverse.rows; ++y) {
    const float* u = full_inverse.ptr<float>(y);
    float* z = result.depth_m.ptr<float>(y);
    for (int x = 0; x < full_inverse.cols; ++x) z[x] = 1.0f / std::clamp(u[x], far_inverse, near_inverse);
  }
  return result;
}

}  // namespace

StatusOr<std::vector<DepthMap>> ComputePlaneSweepDepth(const std::vector<View>& views,
                                                       const PlaneSweepOptions& options,
                                                       const PlaneSweepProgressCallback& progress) {
  const auto start = std::chrono::steady_clock::now();
  PX_RETURN_IF_ERROR(CheckInputs(views, options));
  const ScopedNumThreads threads(options.num_threads);
  std::vector<WorkingView> working;
  working.reserve(views.size());
  for (const View& view : views) working.push_back(MakeWorkingView(view, options.working_scale));

  std::vector<DepthMap> maps;
  maps.reserve(views.size());
  double mean_confidence = 0;
  for (int i = 0; i < static_cast<int>(views.size()); ++i) {
    if (progress && !progress(static_cast<double>(i) / views.size())) {
      return CancelledError("depth cancelled after " + std::to_string(i) + " of " + std::to_string(views.size()) +
                            " views");
    }
    maps.push_back(SweepReference(views, working, i, options));
    mean_confidence += cv::mean(maps.back().confidence)[0] / views.size();
  }
  if (progress) progress(1.0);
  const double ms = MsSince(start);
  Logger("depth")->info("{} depth maps ({} planes, {} neighbours, scale {}) in {:.0f} ms, mean confidence {:.2f}",
                        maps.size(),
                        options.num_planes,
                        options.num_neighbors,
                        options.working_scale,
                        ms,
                        mean_confidence);
  // Below this most of the image is textureless, out of the depth range or badly calibrated.
  constexpr double kLowMeanConfidence = 0.2;
  if (mean_confidence < kLowMeanConfidence) {
    Logger("depth")->warn(
        "mean depth confidence {:.2f} is low: little texture, depth outside [{}, {}] m, or a "
        "calibration that does not match the views",
        mean_confidence,
        options.min_depth_m,
        options.max_depth_m);
  }
  return maps;
}

StatusOr<DepthMap> ComputePlaneSweepDepthForView(const std::vector<View>& views,
                                                 int reference_index,
                                                 const PlaneSweepOptions& options) {
  PX_RETURN_IF_ERROR(CheckInputs(views, options));
  if (reference_index < 0 || reference_index >= static_cast<int>(views.size())) {
    return OutOfRangeError("reference view index " + std::to_string(reference_index) + " is outside [0, " +
                           std::to_string(views.size()) + ")");
  }
  const ScopedNumThreads threads(options.num_threads);
  std::vector<WorkingView> working;
  working.reserve(views.size());
  for (const View& view : views) working.push_back(MakeWorkingView(view, options.working_scale));
  return SweepReference(views, working, reference_index, options);
}

}  // namespace px
