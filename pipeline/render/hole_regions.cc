#include "pipeline/render/hole_regions.h"

#include <algorithm>
#include <utility>

namespace px::render {
namespace {

// Runs [first, last] of non-zero entries of `counts` (CV_32S, one row or one column), with runs
// separated by at most `max_gap` zero entries merged.
std::vector<std::pair<int, int>> Runs(const cv::Mat& counts, int max_gap) {
  const int n = static_cast<int>(counts.total());
  const int* c = counts.ptr<int>();
  std::vector<std::pair<int, int>> runs;
  for (int i = 0; i < n; ++i) {
    if (c[i] == 0) continue;
    if (!runs.empty() && i - runs.back().second - 1 <= max_gap) {
      runs.back().second = i;
    } else {
      runs.emplace_back(i, i);
    }
  }
  return runs;
}

}  // namespace

std::vector<cv::Rect> HoleRegions(const cv::Mat& coverage, int margin_px) {
  std::vector<cv::Rect> regions;
  const cv::Mat holes = coverage == 0;  // 255 at holes
  cv::Mat column_counts;
  cv::reduce(holes, column_counts, 0, cv::REDUCE_SUM, CV_32S);
  const cv::Rect frame(0, 0, coverage.cols, coverage.rows);
  for (const auto& [x0, x1] : Runs(column_counts, margin_px)) {
    cv::Mat row_counts;
    cv::reduce(holes.colRange(x0, x1 + 1), row_counts, 1, cv::REDUCE_SUM, CV_32S);
    for (const auto& [y0, y1] : Runs(row_counts, margin_px)) {
      const cv::Rect box(x0 - margin_px, y0 - margin_px, x1 - x0 + 1 + 2 * margin_px, y1 - y0 + 1 + 2 * margin_px);
      regions.push_back(box & frame);
    }
  }
  return regions;
}

}  // namespace px::render
