#include "pipeline/depth/sub_plane.h"

#include <algorithm>
#include <cmath>

#include "pipeline/core/check.h"
#include "pipeline/depth/zncc_cost.h"

namespace px::depth {

void RefineAroundWinners(const std::vector<cv::Mat>& raw, int search_planes, bool wide_fit, cv::Mat* winner) {
  PX_CHECK(raw.size() >= 2 && winner->type() == CV_32FC1 && winner->size() == raw[0].size());
  const int planes = static_cast<int>(raw.size());
  cv::parallel_for_(cv::Range(0, winner->rows), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      float* w = winner->ptr<float>(y);
      for (int x = 0; x < winner->cols; ++x) {
        const int centre = std::clamp(static_cast<int>(std::lround(w[x])), 0, planes - 1);
        int best = centre;
        float best_cost = raw[centre].at<float>(y, x);
        for (int p = std::max(0, centre - search_planes); p <= std::min(planes - 1, centre + search_planes); ++p) {
          const float c = raw[p].at<float>(y, x);
          if (c < best_cost) {
            best_cost = c;
            best = p;
          }
        }
        if (best_cost >= kNoDataCost) continue;  // no raw evidence: keep the aggregate's choice
        float offset = 0;
        if (wide_fit && best > 1 && best + 2 < planes) {
          // Least-squares parabola through five points (offsets -2..2), as SelectPlanes: it
          // averages out small kinks of a finely sampled curve.
          const float b2 = raw[best - 2].at<float>(y, x), b1 = raw[best - 1].at<float>(y, x);
          const float a1 = raw[best + 1].at<float>(y, x), a2 = raw[best + 2].at<float>(y, x);
          const float slope = (2 * (a2 - b2) + (a1 - b1)) / 10.0f;
          const float half_curvature = (2 * (b2 + a2) - (b1 + a1) - 2 * best_cost) / 14.0f;
          if (half_curvature > 1e-6f && std::max({b2, b1, a1, a2}) < kNoDataCost) {
            w[x] = static_cast<float>(best) + std::clamp(-slope / (2 * half_curvature), -1.0f, 1.0f);
            continue;
          }
        }
        if (best > 0 && best + 1 < planes) {
          const float before = raw[best - 1].at<float>(y, x), after = raw[best + 1].at<float>(y, x);
          const float curvature = before - 2 * best_cost + after;
          if (curvature > 1e-6f && before < kNoDataCost && after < kNoDataCost) {
            offset = std::clamp(0.5f * (before - after) / curvature, -0.5f, 0.5f);
          }
        }
        w[x] = static_cast<float>(best) + offset;
      }
    }
  });
}

}  // namespace px::depth
