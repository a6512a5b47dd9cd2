#include "pipeline/depth/semi_global.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "pipeline/core/check.h"

namespace px::depth {
namespace {

// One path step: out[d] = cost[d] + min(prev[d], prev[d -+ 1] + p1, min(prev) + p2) - min(prev);
// returns min(out). prev and out hold num_planes values.
float PathStep(const float* __restrict cost, const float* __restrict prev, int num_planes, float p1, float p2,
               float prev_min, float* __restrict out) {
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

// One sweep over the rows in direction `dy` (+1: top to bottom with paths from the left, top,
// and (8 paths) top-left and top-right; -1: the mirror image), adding its path costs into sum
// (rows x cols x planes, pixel-major).
void Sweep(const std::vector<cv::Mat>& slices, const cv::Mat& gray, const SemiGlobalOptions& options, int dy,
           std::vector<float>* sum) {
  const int rows = gray.rows, cols = gray.cols, planes = static_cast<int>(slices.size());
  const size_t row_size = static_cast<size_t>(cols) * planes;
  const bool diagonals = options.num_paths == 8;
  const int num_vertical = diagonals ? 3 : 1;  // offsets dx = 0, -1, +1 (times dy's direction)
  std::vector<float> cost(row_size), along(planes), along_next(planes);
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
    float* s = sum->data() + static_cast<size_t>(y) * row_size;
    // The in-row path.
    float along_min = 0;
    for (int i = 0; i < cols; ++i) {
      const int x = dx > 0 ? i : cols - 1 - i;
      const float* c = cost.data() + static_cast<size_t>(x) * planes;
      if (i == 0) {
        std::copy_n(c, planes, along.data());
        along_min = MinOf(along.data(), planes);
      } else {
        along_min = PathStep(c, along.data(), planes, options.step_penalty, JumpPenalty(options, g[x], g[x - dx]),
                             along_min, along_next.data());
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
          current_min[k][x] =
              PathStep(c, previous[k].data() + static_cast<size_t>(from) * planes, planes, options.step_penalty,
                       JumpPenalty(options, g[x], prev_gray[from]), previous_min[k][from], out);
        }
        AddTo(out, planes, s + static_cast<size_t>(x) * planes);
      }
    }
    std::swap(previous, current);
    std::swap(previous_min, current_min);
    prev_gray = g;
  }
}

}  // namespace

void AggregateSemiGlobal(const cv::Mat& gray, const SemiGlobalOptions& options, std::vector<cv::Mat>* slices) {
  PX_CHECK(gray.type() == CV_32FC1 && slices->size() >= 2) << "grey reference and at least two planes";
  PX_CHECK(options.num_paths == 4 || options.num_paths == 8) << "4 or 8 paths, got " << options.num_paths;
  const int planes = static_cast<int>(slices->size());
  const size_t volume_size = gray.total() * planes;
  std::vector<float> forward(volume_size, 0.0f), backward(volume_size, 0.0f);
  cv::parallel_for_(cv::Range(0, 2), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) Sweep(*slices, gray, options, i == 0 ? 1 : -1, i == 0 ? &forward : &backward);
  });
  const float scale = 1.0f / static_cast<float>(options.num_paths);
  const int cols = gray.cols;
  cv::parallel_for_(cv::Range(0, gray.rows), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      const float* f = forward.data() + static_cast<size_t>(y) * cols * planes;
      const float* b = backward.data() + static_cast<size_t>(y) * cols * planes;
      for (int d = 0; d < planes; ++d) {
        float* out = (*slices)[d].ptr<float>(y);
        for (int x = 0; x < cols; ++x) {
          const size_t i = static_cast<size_t>(x) * planes + d;
          out[x] = (f[i] + b[i]) * scale;
        }
      }
    }
  });
}

}  // namespace px::depth
