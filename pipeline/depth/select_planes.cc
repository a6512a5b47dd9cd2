#include "pipeline/depth/select_planes.h"

#include <algorithm>
#include <limits>

#include "pipeline/core/check.h"
#include "pipeline/depth/zncc_cost.h"

namespace px::depth {
namespace {

constexpr float kHuge = std::numeric_limits<float>::max();

// The per-plane loops are separate functions so that __restrict holds and they vectorise.

void UpdateBest(
    const float* __restrict cost, int cols, float plane, float* __restrict best, float* __restrict best_plane) {
  for (int x = 0; x < cols; ++x) {
    const float c = cost[x], b = best[x], bp = best_plane[x];
    best[x] = std::min(c, b);
    best_plane[x] = c < b ? plane : bp;
  }
}

// For plane p: tracks the curve's maximum, the lowest local minimum not adjacent to the
// winner, and the costs just left and right of the winner (for the parabola). Plane positions
// are whole numbers here, so "adjacent" tests use a 0.25 margin.
void ScanPlaneExtremes(const float* __restrict previous,
                       const float* __restrict cost,
                       const float* __restrict next,
                       const float* __restrict best_plane,
                       int cols,
                       float plane,
                       float* __restrict highest,
                       float* __restrict second) {
  for (int x = 0; x < cols; ++x) {
    const float c = cost[x], s = second[x], distance = plane - best_plane[x];
    highest[x] = std::max(highest[x], c);
    const float local_minimum = c <= previous[x] ? c : kHuge;
    const float candidate = c <= next[x] ? local_minimum : kHuge;
    second[x] = std::min(s, std::abs(distance) > 1.5f ? candidate : kHuge);
  }
}

// Records this plane's cost where it lies 1 or 2 planes before or after the winner.
void ScanPlaneNeighbours(const float* __restrict cost,
                         const float* __restrict best_plane,
                         int cols,
                         float plane,
                         float* __restrict before2,
                         float* __restrict before1,
                         float* __restrict after1,
                         float* __restrict after2) {
  for (int x = 0; x < cols; ++x) {
    const float c = cost[x], offset = plane - best_plane[x];
    const float b2 = before2[x], b1 = before1[x], a1 = after1[x], a2 = after2[x];
    before2[x] = std::abs(offset + 2.0f) < 0.25f ? c : b2;
    before1[x] = std::abs(offset + 1.0f) < 0.25f ? c : b1;
    after1[x] = std::abs(offset - 1.0f) < 0.25f ? c : a1;
    after2[x] = std::abs(offset - 2.0f) < 0.25f ? c : a2;
  }
}

void Finish(const float* __restrict best,
            const float* __restrict best_plane,
            const float* __restrict highest,
            const float* __restrict second,
            const float* __restrict before2,
            const float* __restrict before1,
            const float* __restrict after1,
            const float* __restrict after2,
            int cols,
            bool wide_fit,
            float* __restrict plane_out,
            float* __restrict confidence_out) {
  for (int x = 0; x < cols; ++x) {
    const float c0 = best[x], b2 = before2[x], b1 = before1[x], a1 = after1[x], a2 = after2[x], s = second[x];
    // Neighbours stay kHuge beyond the ends of the range and are kNoDataCost where unsampled.
    // Three-point parabola through the winner and its neighbours.
    const float curvature3 = b1 - 2 * c0 + a1;
    const float offset3 = std::clamp(0.5f * (b1 - a1) / std::max(curvature3, 1e-6f), -0.5f, 0.5f);
    const bool refine3 = (b1 < kNoDataCost) & (a1 < kNoDataCost) & (curvature3 > 1e-6f);
    // Least-squares parabola through five points (offsets -2..2): slope = sum(k c_k) / 10,
    // half-curvature = sum((k^2 - 2) c_k) / 14. Averages out small kinks in the cost curve.
    const float slope = (2 * (a2 - b2) + (a1 - b1)) / 10.0f;
    const float half_curvature = (2 * (b2 + a2) - (b1 + a1) - 2 * c0) / 14.0f;
    const float offset5 = std::clamp(-slope / (2 * std::max(half_curvature, 1e-6f)), -1.0f, 1.0f);
    const bool refine5 = wide_fit & (b2 < kNoDataCost) & (a2 < kNoDataCost) & refine3 & (half_curvature > 1e-6f);
    plane_out[x] = best_plane[x] + (refine5 ? offset5 : (refine3 ? offset3 : 0.0f));
    const float c2 = s < kHuge ? s : highest[x];
    const float distinct = 1.0f - c0 / std::max(c2, 1e-6f);
    const float confidence = std::clamp(distinct * (1.0f - c0), 0.0f, 1.0f);
    confidence_out[x] = c0 < kNoDataCost ? confidence : 0.0f;
  }
}

}  // namespace

PlaneSelection SelectPlanes(const std::vector<cv::Mat>& cost_volume, int fit_half_width) {
  PX_CHECK(cost_volume.size() >= 2) << "need at least two planes";
  const int num_planes = static_cast<int>(cost_volume.size());
  const cv::Size size = cost_volume[0].size();
  const int cols = size.width;
  const bool wide_fit = fit_half_width >= 2;
  PlaneSelection selection;
  selection.plane.create(size, CV_32F);
  selection.confidence.create(size, CV_32F);
  cv::parallel_for_(cv::Range(0, size.height), [&](const cv::Range& rows) {
    std::vector<float> buffer(8 * cols);
    float* best = buffer.data();
    float* best_plane = best + cols;
    float* highest = best_plane + cols;
    float* second = highest + cols;
    float* before2 = second + cols;
    float* before1 = before2 + cols;
    float* after1 = before1 + cols;
    float* after2 = after1 + cols;
    for (int y = rows.start; y < rows.end; ++y) {
      std::fill_n(best, cols, kHuge);
      std::fill_n(best_plane, cols, 0.0f);
      for (int p = 0; p < num_planes; ++p)
        UpdateBest(cost_volume[p].ptr<float>(y), cols, static_cast<float>(p), best, best_plane);
      std::fill_n(highest, cols, 0.0f);
      std::fill_n(second, cols, kHuge);
      std::fill_n(before2, 4 * cols, kHuge);
      for (int p = 0; p < num_planes; ++p) {
        // Beyond the ends the curve counts as rising, so an end plane can be a local minimum.
        const float* cost = cost_volume[p].ptr<float>(y);
        const float* previous = p > 0 ? cost_volume[p - 1].ptr<float>(y) : cost;
        const float* next = p + 1 < num_planes ? cost_volume[p + 1].ptr<float>(y) : cost;
        ScanPlaneExtremes(previous, cost, next, best_plane, cols, static_cast<float>(p), highest, second);
        ScanPlaneNeighbours(cost, best_plane, cols, static_cast<float>(p), before2, before1, after1, after2);
      }
      Finish(best,
             best_plane,
             highest,
             second,
             before2,
             before1,
             after1,
             after2,
             cols,
             wide_fit,
             selection.plane.ptr<float>(y),
             selection.confidence.ptr<float>(y));
    }
  });
  return selection;
}

}  // namespace px::depth
