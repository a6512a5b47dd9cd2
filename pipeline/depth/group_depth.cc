#include "pipeline/depth/group_depth.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "pipeline/core/check.h"
#include "pipeline/depth/segment_match_cost.h"
#include "pipeline/depth/zncc_cost.h"

namespace px::depth {
namespace {

// Each pixel's group (-1: none), CV_32S.
cv::Mat GroupImage(const cv::Mat& labels, const std::vector<int>& group_of) {
  cv::Mat groups(labels.size(), CV_32S);
  for (int y = 0; y < labels.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    int* g = groups.ptr<int>(y);
    for (int x = 0; x < labels.cols; ++x) g[x] = group_of[l[x]];
  }
  return groups;
}

// Per group, the sampled pixels whose 8 neighbours `reach` away are all in the group.
std::vector<std::vector<cv::Point>> InteriorSamples(const cv::Mat& groups, int num_groups, int reach, int step) {
  std::vector<std::vector<cv::Point>> samples(num_groups);
  for (int y = reach; y < groups.rows - reach; y += step) {
    for (int x = reach; x < groups.cols - reach; x += step) {
      const int g = groups.at<int>(y, x);
      if (g < 0) continue;
      bool interior = true;
      for (int dy = -1; dy <= 1 && interior; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          if (groups.at<int>(y + dy * reach, x + dx * reach) != g) {
            interior = false;
            break;
          }
        }
      }
      if (interior) samples[g].emplace_back(x, y);
    }
  }
  return samples;
}

InversePlane Scaled(const InversePlane& plane, double scale) {
  return InversePlane{plane.a * scale, plane.b * scale, plane.c * scale};
}

}  // namespace

GroupDepthStats RefineGroupDepths(const WorkingView& reference,
                                  const std::vector<const WorkingView*>& neighbours,
                                  const std::vector<int>& group_of,
                                  const GroupDepthOptions& options,
                                  SegmentImage* image) {
  PX_CHECK(image != nullptr && image->labels.type() == CV_32SC1 && image->labels.size() == reference.gray.size());
  PX_CHECK(group_of.size() == image->planes.size()) << "one group entry per segment";
  PX_CHECK(options.pixel_inverse_depth > 0 && options.interior_px >= 1 && options.sample_step_px >= 1 &&
           options.sample_step_px <= 16 && options.search_px > 0 && options.search_px <= 4 && options.step_px > 0 &&
           options.step_px <= options.search_px && options.min_samples >= 16 &&
           options.max_samples >= options.min_samples);
  PX_CHECK(neighbours.size() <= 16) << "at most 16 neighbours";
  GroupDepthStats stats;
  const int num_groups = group_of.empty() ? 0 : *std::max_element(group_of.begin(), group_of.end()) + 1;
  if (num_groups == 0 || neighbours.empty()) return stats;

  const cv::Mat groups = GroupImage(image->labels, group_of);
  std::vector<std::vector<cv::Point>> samples =
      InteriorSamples(groups, num_groups, options.interior_px, options.sample_step_px);
  for (std::vector<cv::Point>& pixels : samples) {
    if (static_cast<int>(pixels.size()) <= options.max_samples) continue;
    // Evenly spaced in scan order, so the samples still cover the whole interior.
    const double stride = static_cast<double>(pixels.size()) / options.max_samples;
    std::vector<cv::Point> spread;
    spread.reserve(options.max_samples);
    for (int i = 0; i < options.max_samples; ++i) spread.push_back(pixels[static_cast<size_t>(i * stride)]);
    pixels = std::move(spread);
  }
  const cv::Mat& ref_gray = reference.gray;
  const std::vector<GrayNeighbour> gray_neighbours = GrayNeighbours(reference, neighbours);

  const int steps = static_cast<int>(std::lround(options.search_px / options.step_px));
  double total_shift_px = 0;
  for (int g = 0; g < num_groups; ++g) {
    const std::vector<cv::Point>& pixels = samples[g];
    if (static_cast<int>(pixels.size()) < options.min_samples) continue;
    if (GreyVariance(ref_gray, pixels) < options.min_texture_stddev * options.min_texture_stddev) continue;
    // The group's plane (its members share it) and its inverse depth at the samples' centre.
    const int first_member = image->labels.at<int>(pixels[pixels.size() / 2]);
    const InversePlane plane = image->planes[first_member];
    cv::Point2d centre(0, 0);
    for (const cv::Point& p : pixels) centre += cv::Point2d(p.x, p.y);
    centre *= 1.0 / pixels.size();
    const double u_centre = plane.At(centre.x, centre.y);
    if (!(u_centre > 0)) continue;
    ++stats.groups;
    // Scale factor per step: one step moves the centre's disparity by step_px.
    const double scale_per_step = options.step_px * options.pixel_inverse_depth / u_centre;
    // The cost is smooth and single-welled over a fraction of a pixel: start with the steps
    // around the current depth and walk downhill, at most `steps` either way.
    std::vector<double> costs(2 * steps + 1, -1);
    const auto cost_at = [&](int k) {
      double& cost = costs[k + steps];
      if (cost < 0) cost = BestHalfZnccCost(ref_gray, gray_neighbours, pixels, Scaled(plane, 1 + k * scale_per_step));
      return cost;
    };
    int best = 0;
    while (true) {
      const double here = cost_at(best);
      if (best > -steps && cost_at(best - 1) < here) {
        --best;
      } else if (best < steps && cost_at(best + 1) < here) {
        ++best;
      } else {
        break;
      }
    }
    if (cost_at(best) >= kNoDataCost) continue;
    double offset = best;
    if (best > -steps && best < steps) {
      const double left = cost_at(best - 1), mid = cost_at(best), right = cost_at(best + 1);
      const double curvature = left - 2 * mid + right;
      if (curvature > 0) offset += std::clamp(0.5 * (left - right) / curvature, -0.5, 0.5);
    }
    if (offset == 0) continue;
    const double scale = 1 + offset * scale_per_step;
    for (size_t s = 0; s < group_of.size(); ++s) {
      if (group_of[s] == g) image->planes[s] = Scaled(image->planes[s], scale);
    }
    ++stats.moved;
    total_shift_px += std::abs(offset) * options.step_px;
  }
  if (stats.groups > 0) stats.mean_abs_shift_px = total_shift_px / stats.groups;
  return stats;
}

}  // namespace px::depth
