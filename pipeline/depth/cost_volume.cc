#include "pipeline/depth/cost_volume.h"

#include <mutex>

#include "pipeline/core/check.h"
#include "pipeline/depth/best_half_aggregation.h"
#include "pipeline/depth/cost_filter.h"
#include "pipeline/depth/plane_homography.h"
#include "pipeline/depth/plane_warp.h"
#include "pipeline/depth/zncc_cost.h"

namespace px::depth {

InverseDepthPlanes MakeInverseDepthPlanes(double min_depth_m, double max_depth_m, int count) {
  PX_CHECK(count >= 2 && min_depth_m > 0 && max_depth_m > min_depth_m);
  InverseDepthPlanes planes;
  planes.count = count;
  planes.far_inverse_m = 1.0 / max_depth_m;
  planes.step_inverse_m = (1.0 / min_depth_m - planes.far_inverse_m) / (count - 1);
  return planes;
}

CostVolume BuildCostVolume(const WorkingView& ref,
                           const std::vector<const WorkingView*>& neighbours,
                           const InverseDepthPlanes& planes,
                           const CostVolumeOptions& options) {
  const cv::Size size = ref.gray.size();
  const ReferenceWindows windows =
      PrepareReferenceWindows(ref.gray, options.window_radius_px, options.min_texture_stddev);
  const bool filter_costs = options.filter_radius_px > 0;
  const CostFilterGuide guide =
      filter_costs ? PrepareCostFilterGuide(ref.gray, options.filter_radius_px, options.filter_eps) : CostFilterGuide();
  CostVolume volume;
  volume.slices.resize(planes.count);
  volume.best_unfiltered_cost = cv::Mat(size, CV_32F, cv::Scalar(kNoDataCost));
  cv::Mat typical_sum = cv::Mat::zeros(size, CV_32F), typical_count = cv::Mat::zeros(size, CV_32F);
  // Per pixel, how many of the farthest quarter of the planes (index 0 is the farthest) the
  // neighbours sampled.
  const int far_planes = std::max(1, planes.count / 4);
  cv::Mat planes_sampled = cv::Mat::zeros(size, CV_32F);
  constexpr int kTypicalPlaneStep = 4;
  std::mutex merge_mutex;
  // Planes are independent: each worker takes a range of them with its own buffers.
  cv::parallel_for_(cv::Range(0, planes.count), [&](const cv::Range& range) {
    cv::Mat sampled_here = cv::Mat::zeros(size, CV_32F);  // of the far planes
    cv::Mat best_here(size, CV_32F, cv::Scalar(kNoDataCost));
    cv::Mat sum_here = cv::Mat::zeros(size, CV_32F), count_here = cv::Mat::zeros(size, CV_32F), sampled_slice;
    cv::Mat warped, valid;
    ZnccWorkspace zncc;
    std::vector<cv::Mat> costs(neighbours.size());
    AggregationWorkspace aggregation;
    CostFilterWorkspace filter;
    for (int p = range.start; p < range.end; ++p) {
      const double depth_m = 1.0 / planes.InverseDepth(p);
      for (size_t k = 0; k < neighbours.size(); ++k) {
        const WorkingView& src = *neighbours[k];
        const Eigen::Matrix3d h =
            PlaneHomography(ref.camera, ref.cam_from_world, src.camera, src.cam_from_world, depth_m);
        WarpIntoReference(src.gray, h, size, &warped);
        ValidSampleMask(h, src.gray.size(), options.window_radius_px, size, &valid);
        ComputeZnccCost(windows, warped, valid, &zncc, &costs[k]);
      }
      cv::Mat& slice = volume.slices[p];
      AggregateBestHalf(costs, &aggregation, &slice);
      if (p < far_planes) cv::add(sampled_here, cv::Scalar(1), sampled_here, slice < kNoDataCost);
      cv::min(best_here, slice, best_here);
      if (p % kTypicalPlaneStep == 0) {
        sampled_slice = slice < kNoDataCost;
        cv::add(sum_here, slice, sum_here, sampled_slice);
        cv::add(count_here, cv::Scalar(1), count_here, sampled_slice);
      }
      if (filter_costs) FilterCostSlice(guide, &filter, &slice);
    }
    const std::lock_guard<std::mutex> lock(merge_mutex);
    planes_sampled += sampled_here;
    cv::min(volume.best_unfiltered_cost, best_here, volume.best_unfiltered_cost);
    typical_sum += sum_here;
    typical_count += count_here;
  });
  volume.sampled = planes_sampled >= 0.5 * far_planes;
  volume.typical_unfiltered_cost = cv::Mat(size, CV_32F, cv::Scalar(kNoDataCost));
  cv::divide(typical_sum, typical_count, volume.typical_unfiltered_cost);
  volume.typical_unfiltered_cost.setTo(kNoDataCost, typical_count == 0);
  return volume;
}

}  // namespace px::depth
