#include "pipeline/depth/semi_global.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>

#include "pipeline/core/check.h"

namespace px::depth {
namespace {

// One path step: out[d] = cost[d] + min(prev[d], prev[d -+ 1] + p1, min(prev) + p2) - min(prev);
// returns min(out). prev and out hold num_planes values.
float PathStep(const float* __restrict cost,
               const float* __restrict prev,
               int num_planes,
               float p1,
               float p2,
               float prev_min,
               float* __restrict out) {
  const float jump = prev_min + p2;
  float out_min = std::numeric_limits<float>::max();
  for (int d = 0; d < num_planes; ++d) {
    float best = std::min(prev[d], jump);
    if (d > 0) best = std::min(best, prev[d - 1] + p1);
    if (d + 1 < num_planes) best = std::min(best, prev[d + 1] + p1);
    const float value = cost[d] + best - prev_min;
    out[d] = value;
    out_min = std::min(out_min, value);
  }
  return out_min;
}

float MinOf(const float* values, int n) { return *std::min_element(values, values + n); }

void AddTo(const float* __restrict values, int n, float* __restrict sum) {
  for (int i = 0; i < n; ++i) sum[i] += values[i];
}

// Jump penalty between two pixels, lowered across a grey edge.
float JumpPenalty(const SemiGlobalOptions& options, float a, float b) {
  return std::abs(a - b) >= options.edge_gray ? std::max(options.step_penalty, options.jump_penalty / 3)
                                              : options.jump_penalty;
}

// The aggregate being built: one CV_32F slice per plane, and a lock per row so that the forward
// and backward sweeps (two threads) can add their finished rows in either order.
struct Aggregate {
  std::vector<cv::Mat> slices;
  std::vector<std::mutex> row_locks;
};

// Adds one row of path costs (pixel-major: cols x planes) times `scale` into row y of the aggregate.
void AddRow(const std::vector<float>& row_sum, int y, float scale, Aggregate* aggregate) {
  const int planes = static_cast<int>(aggregate->slices.size());
  const std::lock_guard<std::mutex> lock(aggregate->row_locks[y]);
  for (int d = 0; d < planes; ++d) {
    float* out = aggregate->slices[d].ptr<float>(y);
    for (int x = 0; x < aggregate->slices[d].cols; ++x) out[x] += row_sum[static_cast<size_t>(x) * planes + d] * scale;
  }
}

// One sweep over the rows in direction `dy` (+1: top to bottom with paths from the left, top,
// and (8 paths) top-left and top-right; -1: the mirror image). Only the previous row's path
// costs are kept; each finished row's sum of paths, times `scale`, goes into the aggregate.
void Sweep(const std::vector<cv::Mat>& slices,
           const cv::Mat& gray,
           const SemiGlobalOptions& options,
           int dy,
           float scale,
           Aggregate* aggregate) {
  const int rows = gray.rows, cols = gray.cols, planes = static_cast<int>(slices.size());
  const size_t row_size = static_cast<size_t>(cols) * planes;
  const bool diagonals = options.num_paths == 8;
  const int num_vertical = diagonals ? 3 : 1;  // from the previous row at x + 0, -1, +1 (both diagonals, either sweep)
  std::vector<float> cost(row_size), row_sum(row_size), along(planes), along_next(planes);
  // Path costs of the previous row for each vertical/diagonal direction, and their minima.
  std::vector<std::vector<float>> previous(num_vertical, std::vector<float>(row_size)),
      current(num_vertical, std::vector<float>(row_size));
  std::vector<std::vector<float>> previous_min(num_vertical, std::vector<float>(cols)),
      current_min(num_vertical, std::vector<float>(cols));
  const int dx = dy;  // the in-row path runs left to right when sweeping down, right to left up
  const float* prev_gray = nullptr;
  for (int step = 0; step < rows; ++step) {
    const int y = dy > 0 ? step : rows - 1 - step;
    for (int d = 0; d < planes; ++d) {
      const float* c = slices[d].ptr<float>(y);
      for (int x = 0; x < cols; ++x) cost[static_cast<size_t>(x) * planes + d] = c[x];
    }
    const float* g = gray.ptr<float>(y);
    std::fill(row_sum.begin(), row_sum.end(), 0.0f);
    float* s = row_sum.data();
    // The in-row path.
    float along_min = 0;
    for (int i = 0; i < cols; ++i) {
      const int x = dx > 0 ? i : cols - 1 - i;
      const float* c = cost.data() + static_cast<size_t>(x) * planes;
      if (i == 0) {
        std::copy_n(c, planes, along.data());
        along_min = MinOf(along.data(), planes);
      } else {
        along_min = PathStep(c,
                             along.data(),
                             planes,
                             options.step_penalty,
                             JumpPenalty(options, g[x], g[x - dx]),
                             along_min,
                             along_next.data());
        std::swap(along, along_next);
      }
      AddTo(along.data(), planes, s + static_cast<size_t>(x) * planes);
    }
    // Paths from the previous row: straight, and (8 paths) from either diagonal.
    for (int k = 0; k < num_vertical; ++k) {
      const int offset = k == 0 ? 0 : (k == 1 ? -1 : 1);
      for (int x = 0; x < cols; ++x) {
        const float* c = cost.data() + static_cast<size_t>(x) * planes;
        float* out = current[k].data() + static_cast<size_t>(x) * planes;
        const int from = x + offset;
        if (step == 0 || from < 0 || from >= cols) {
          std::copy_n(c, planes, out);
          current_min[k][x] = MinOf(out, planes);
        } else {
          current_min[k][x] = PathStep(c,
                                       previous[k].data() + static_cast<size_t>(from) * planes,
                                       planes,
                                       options.step_penalty,
                                       JumpPenalty(options, g[x], prev_gray[from]),
                                       previous_min[k][from],
                                       out);
        }
        AddTo(out, planes, s + static_cast<size_t>(x) * planes);
      }
    }
    AddRow(row_sum, y, scale, aggregate);
    std::swap(previous, current);
    std::swap(previous_min, current_min);
    prev_gray = g;
  }
}

}  // namespace

std::vector<cv::Mat> AggregateSemiGlobal(const cv::Mat& gray,
                                         const SemiGlobalOptions& options,
                                         const std::vector<cv::Mat>& slices) {
  PX_CHECK(gray.type() == CV_32FC1 && slices.size() >= 2) << "grey reference and at least two planes";
  PX_CHECK(options.num_paths == 4 || options.num_paths == 8) << "4 or 8 paths, got " << options.num_paths;
  Aggregate aggregate{std::vector<cv::Mat>(slices.size()), std::vector<std::mutex>(gray.rows)};
  for (cv::Mat& slice : aggregate.slices) slice = cv::Mat::zeros(gray.size(), CV_32F);
  const float scale = 1.0f / static_cast<float>(options.num_paths);
  cv::parallel_for_(cv::Range(0, 2), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) Sweep(slices, gray, options, i == 0 ? 1 : -1, scale, &aggregate);
  });
  return std::move(aggregate.slices);
}

}  // namespace px::depth
