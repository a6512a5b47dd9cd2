#include "pipeline/depth/plane_sweep.h"

#include <algorithm>
#include <chrono>
#include <limits>
#include <cmath>
#include <sstream>
#include <string>
#include <mutex>

#include <opencv2/imgproc.hpp>

#include "pipeline/core/log.h"
#include "pipeline/depth/depth_cleanup.h"
#include "pipeline/depth/best_half_aggregation.h"
#include "pipeline/depth/cost_filter.h"
#include "pipeline/depth/plane_homography.h"
#include "pipeline/depth/plane_warp.h"
#include "pipeline/depth/zncc_cost.h"
#include "pipeline/depth/select_planes.h"

namespace px {
namespace {

using depth::kNoDataCost;

// A view reduced to what matching needs, at the working scale.
struct WorkingView {
  cv::Mat bgr;   // CV_8UC3, guide for edge-aware filtering
  cv::Mat gray;  // CV_32F in [0, 1]
  CameraModel camera;
  Rigid3 cam_from_world;
};

// Sets OpenCV's worker count for the lifetime of the guard (0 leaves it alone).
class ScopedNumThreads {
 public:
  explicit ScopedNumThreads(int num_threads) : previous_(cv::getNumThreads()), active_(num_threads > 0) {
    if (active_) cv::setNumThreads(num_threads);
  }
  ~ScopedNumThreads() {
    if (active_) cv::setNumThreads(previous_);
  }
  ScopedNumThreads(const ScopedNumThreads&) = delete;
  ScopedNumThreads& operator=(const ScopedNumThreads&) = delete;

 private:
  int previous_;
  bool active_;
};

std::string ViewName(const View& view) { return "view " + std::to_string(view.id.value); }

Status CheckInputs(const std::vector<View>& views, const DepthOptions& options) {
  PX_RETURN_IF_ERROR(options.Validate());
  if (!options.HasDepthRange()) {
    std::ostringstream error;
    error << "depth options: depth range [" << options.min_depth_m << ", " << options.max_depth_m
          << "] m is not set (fill it from the rig with WithDefaultDepthRange)";
    return InvalidArgumentError(error.str());
  }
  if (views.size() < 2) {
    return InvalidArgumentError("depth needs at least 2 views, got " + std::to_string(views.size()));
  }
  for (const View& view : views) {
    PX_RETURN_IF_ERROR(view.camera.Validate().WithContext(ViewName(view)));
    if (view.camera.HasDistortion()) {
      return InvalidArgumentError(ViewName(view) + ": camera has lens distortion; depth needs undistorted views");
    }
    if (view.image.type() != CV_8UC3 || view.image.cols != view.camera.width || view.image.rows != view.camera.height) {
      std::ostringstream error;
      error << ViewName(view) << ": image is " << view.image.cols << "x" << view.image.rows << " with "
            << view.image.channels() << " channels, want " << view.camera.width << "x" << view.camera.height
            << " CV_8UC3";
      return InvalidArgumentError(error.str());
    }
    if (!view.cam_from_world.translation.allFinite() || !view.cam_from_world.rotation.coeffs().allFinite()) {
      return InvalidArgumentError(ViewName(view) + ": pose is not finite");
    }
  }
  // The working image must hold a matching window with its interpolation margin.
  const int min_side = 2 * (options.window_radius_px + 2) + 1;
  for (const View& view : views) {
    const CameraModel working = options.working_scale < 1 ? view.camera.Scaled(options.working_scale) : view.camera;
    if (working.width < min_side || working.height < min_side) {
      std::ostringstream error;
      error << ViewName(view) << ": " << view.camera.width << "x" << view.camera.height << " at working scale "
            << options.working_scale << " is " << working.width << "x" << working.height << ", smaller than "
            << min_side << "x" << min_side << " (window radius " << options.window_radius_px << ")";
      return InvalidArgumentError(error.str());
    }
  }
  for (int i = 0; i < static_cast<int>(views.size()); ++i) {
    if (depth::NearestNeighbourViews(views, i, 1).empty()) {
      return InvalidArgumentError(ViewName(views[i]) + ": every other view has the same camera centre (no parallax)");
    }
  }
  return OkStatus();
}

WorkingView MakeWorkingView(const View& view, double scale) {
  WorkingView working;
  working.cam_from_world = view.cam_from_world;
  if (scale < 1) {
    working.camera = view.camera.Scaled(scale);
    cv::resize(view.image, working.bgr, cv::Size(working.camera.width, working.camera.height), 0, 0, cv::INTER_AREA);
  } else {
    working.camera = view.camera;
    working.bgr = view.image;
  }
  cv::Mat gray8;
  cv::cvtColor(working.bgr, gray8, cv::COLOR_BGR2GRAY);
  gray8.convertTo(working.gray, CV_32F, 1.0 / 255.0);
  return working;
}

// Inverse depth of plane p: planes run from the far end (p = 0) to the near end.
struct PlaneSampling {
  double far_inverse_m = 0;
  double step_inverse_m = 0;
  double InverseDepth(double plane) const { return far_inverse_m + plane * step_inverse_m; }
};

// Distance between the reference camera centre and its nearest neighbour's.
double NearestBaselineM(const std::vector<View>& views, int reference, const std::vector<int>& neighbours) {
  const Eigen::Vector3d centre = CameraCentre(views[reference].cam_from_world);
  double nearest = std::numeric_limits<double>::max();
  for (int k : neighbours) nearest = std::min(nearest, (CameraCentre(views[k].cam_from_world) - centre).norm());
  return nearest;
}

PlaneSampling MakePlaneSampling(const DepthOptions& options) {
  PlaneSampling sampling;
  sampling.far_inverse_m = 1.0 / options.max_depth_m;
  sampling.step_inverse_m = (1.0 / options.min_depth_m - sampling.far_inverse_m) / (options.num_planes - 1);
  return sampling;
}

// The plane-sweep cost volume of one reference view: one aggregated, filtered cost slice per
// plane, and which pixels any neighbour sampled at all.
struct CostVolume {
  std::vector<cv::Mat> slices;
  cv::Mat sampled;  // CV_8U, 255 where some plane had a valid neighbour sample
};

CostVolume BuildCostVolume(const WorkingView& ref, const std::vector<const WorkingView*>& neighbours,
                           const PlaneSampling& sampling, const DepthOptions& options) {
  const cv::Size size = ref.gray.size();
  const depth::ReferenceWindows windows =
      depth::PrepareReferenceWindows(ref.gray, options.window_radius_px, options.min_texture_stddev);
  const bool filter_costs = options.cost_filter_radius_px > 0;
  const depth::CostFilterGuide guide =
      filter_costs ? depth::PrepareCostFilterGuide(ref.gray, options.cost_filter_radius_px, options.cost_filter_eps)
                   : depth::CostFilterGuide();
  CostVolume volume;
  volume.slices.resize(options.num_planes);
  volume.sampled = cv::Mat::zeros(size, CV_8U);
  std::mutex sampled_mutex;
  // Planes are independent: each worker takes a range of them with its own buffers.
  cv::parallel_for_(cv::Range(0, options.num_planes), [&](const cv::Range& planes) {
    cv::Mat sampled_here = cv::Mat::zeros(size, CV_8U);
    cv::Mat warped, valid;
    depth::ZnccWorkspace zncc;
    std::vector<cv::Mat> costs(neighbours.size());
    depth::AggregationWorkspace aggregation;
    depth::CostFilterWorkspace filter;
    for (int p = planes.start; p < planes.end; ++p) {
      const double depth_m = 1.0 / sampling.InverseDepth(p);
      for (size_t k = 0; k < neighbours.size(); ++k) {
        const WorkingView& src = *neighbours[k];
        const Eigen::Matrix3d h =
            depth::PlaneHomography(ref.camera, ref.cam_from_world, src.camera, src.cam_from_world, depth_m);
        depth::WarpIntoReference(src.gray, h, size, &warped);
        depth::ValidSampleMask(h, src.gray.size(), options.window_radius_px, size, &valid);
        depth::ComputeZnccCost(windows, warped, valid, &zncc, &costs[k]);
      }
      cv::Mat& slice = volume.slices[p];
      depth::AggregateBestHalf(costs, &aggregation, &slice);
      cv::bitwise_or(sampled_here, slice < kNoDataCost, sampled_here);
      if (filter_costs) depth::FilterCostSlice(guide, &filter, &slice);
    }
    const std::lock_guard<std::mutex> lock(sampled_mutex);
    cv::bitwise_or(volume.sampled, sampled_here, volume.sampled);
  });
  return volume;
}

DepthMap SweepReference(const std::vector<View>& views, const std::vector<WorkingView>& working, int reference,
                        const DepthOptions& options) {
  const WorkingView& ref = working[reference];
  const std::vector<int> neighbour_ids = depth::NearestNeighbourViews(views, reference, options.num_neighbors);
  std::vector<const WorkingView*> neighbours;
  for (int k : neighbour_ids) neighbours.push_back(&working[k]);
  const PlaneSampling sampling = MakePlaneSampling(options);
  CostVolume volume = BuildCostVolume(ref, neighbours, sampling, options);

  // Five-point sub-plane fits when two plane steps move the nearest neighbour's image by at most
  // 0.3 px (measured best on the HCI light field; on coarser sampling the three-point fit wins).
  const double step_px = ref.camera.fx * NearestBaselineM(views, reference, neighbour_ids) * sampling.step_inverse_m;
  const int fit_half_width = 2 * step_px <= 0.3 ? 2 : 1;
  depth::PlaneSelection selection = depth::SelectPlanes(volume.slices, fit_half_width);
  volume.slices.clear();
  selection.confidence.setTo(0, volume.sampled == 0);
  const auto fill_confidence = static_cast<float>(options.fill_confidence);
  // Speckles keep their depth but end up below the fill threshold, so the fill may replace it.
  depth::LowerSpeckleConfidence(selection.plane, options.speckle_max_size_px, /*max_jump_planes=*/2.0f,
                                0.5f * fill_confidence, &selection.confidence);
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
    depth::UpsampleJointBilateral(inverse_depth, selection.confidence, ref.bgr, view.image, &full_inverse,
                                  &result.confidence);
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

StatusOr<std::vector<DepthMap>> ComputeDepth(const std::vector<View>& views, const DepthOptions& options,
                                             const DepthProgressCallback& progress) {
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
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  Logger("depth")->info("{} depth maps ({} planes, {} neighbours, scale {}) in {:.0f} ms, mean confidence {:.2f}",
                        maps.size(), options.num_planes, options.num_neighbors, options.working_scale, ms,
                        mean_confidence);
  // Below this most of the image is textureless, out of the depth range or badly calibrated.
  constexpr double kLowMeanConfidence = 0.2;
  if (mean_confidence < kLowMeanConfidence) {
    Logger("depth")->warn("mean depth confidence {:.2f} is low: little texture, depth outside [{}, {}] m, or a "
                          "calibration that does not match the views",
                          mean_confidence, options.min_depth_m, options.max_depth_m);
  }
  return maps;
}

StatusOr<DepthMap> ComputeDepthForView(const std::vector<View>& views, int reference_index,
                                       const DepthOptions& options) {
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
