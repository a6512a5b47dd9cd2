#include "pipeline/depth/best_half_aggregation.h"

#include <algorithm>

#include "pipeline/core/check.h"
#include "pipeline/depth/zncc_cost.h"

namespace px::depth {
namespace {

// The loops below are separate functions so that __restrict holds and they vectorise.

void CompareExchange(int cols, float* __restrict a, float* __restrict b) {
  for (int x = 0; x < cols; ++x) {
    const float lo = std::min(a[x], b[x]), hi = std::max(a[x], b[x]);
    a[x] = lo;
    b[x] = hi;
  }
}

void CountValid(const float* __restrict cost, int cols, float* __restrict count) {
  for (int x = 0; x < cols; ++x) count[x] += cost[x] < kInvalidCost ? 1.0f : 0.0f;
}

// Adds the sorted row of rank k where it is among the best ceil(count / 2), i.e. 2k < count.
void AddIfKept(
    const float* __restrict sorted, const float* __restrict count, int cols, float twice_rank, float* __restrict sum) {
  for (int x = 0; x < cols; ++x) {
    const float s = sorted[x], n = count[x];
    sum[x] += twice_rank < n ? s : 0.0f;
  }
}

void Mean(const float* __restrict sum, const float* __restrict count, int cols, float* __restrict out) {
  for (int x = 0; x < cols; ++x) {
    const float s = sum[x];
    // ceil(count / 2) by truncation (count is a whole number), which vectorises without SSE4.1.
    const float keep = static_cast<float>(static_cast<int>((count[x] + 1.0f) * 0.5f));
    const float mean = s / std::max(keep, 1.0f);
    out[x] = keep > 0 ? mean : kNoDataCost;
  }
}

}  // namespace

void AggregateBestHalf(const std::vector<cv::Mat>& costs, AggregationWorkspace* workspace, cv::Mat* aggregated) {
  const int num = static_cast<int>(costs.size());
  PX_CHECK(num >= 1 && num <= 16) << "1 to 16 neighbours, got " << num;
  const int cols = costs[0].cols;
  aggregated->create(costs[0].size(), CV_32F);
  workspace->sorted.resize(static_cast<size_t>(num + 2) * cols);
  float* const base = workspace->sorted.data();
  float* const count = base + static_cast<size_t>(num) * cols;  // valid costs per pixel
  float* const sum = count + cols;
  auto row = [&](int k) { return base + static_cast<size_t>(k) * cols; };
  for (int y = 0; y < aggregated->rows; ++y) {
    for (int k = 0; k < num; ++k) std::copy_n(costs[k].ptr<float>(y), cols, row(k));
    // Odd-even transposition sort across the neighbour rows: a fixed network of branch-free
    // compare-exchanges, sorting every pixel's costs at once. Invalid costs sort last.
    for (int round = 0; round < num; ++round) {
      for (int k = round % 2; k + 1 < num; k += 2) CompareExchange(cols, row(k), row(k + 1));
    }
    std::fill_n(count, cols, 0.0f);
    for (int k = 0; k < num; ++k) CountValid(row(k), cols, count);
    std::fill_n(sum, cols, 0.0f);
    for (int k = 0; k < num; ++k) AddIfKept(row(k), count, cols, static_cast<float>(2 * k), sum);
    Mean(sum, count, cols, aggregated->ptr<float>(y));
  }
}

}  // namespace px::depth
