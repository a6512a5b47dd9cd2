#include "pipeline/lattice/tile_edge_fit.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "pipeline/core/order_statistics.h"

namespace px::lattice {
namespace {

// Rows averaged into one cut (noise down, a tilted edge blurs by under 0.2 px at 2 degrees).
constexpr int kCutHalfHeight = 2;
// Cuts per edge at most (beyond this, more cuts add time, not precision).
constexpr int kMaxCuts = 160;
// A fit needs this fraction of the cuts, and at least kMinInliers of them, on its line.
constexpr double kMinInlierFraction = 0.35;
constexpr int kMinInliers = 8;
// With the gap's side known, the first transition reaching this fraction of the cut's strongest.
constexpr float kFirstOfStrongest = 0.4f;

struct Transition {
  double along = 0;     // y of the cut
  double across = 0;    // sub-pixel x of the strongest transition
  double gradient = 0;  // its strength, grey levels per pixel
};

// The strongest transition of `sign` in one cut: central differences of the averaged rows (or
// columns, transposed), the peak refined by a parabola. False when the window leaves the frame
// or holds no such transition.
bool StrongestTransition(const cv::Mat& grey,
                         bool transposed,
                         int y,
                         double x_begin,
                         double x_end,
                         int sign,
                         int gap_side,
                         Transition* out) {
  const int across_size = transposed ? grey.rows : grey.cols, along_size = transposed ? grey.cols : grey.rows;
  const int x0 = std::max(1, static_cast<int>(std::floor(x_begin)));
  const int x1 = std::min(across_size - 2, static_cast<int>(std::ceil(x_end)));
  if (x1 - x0 < 2) return false;
  const int y0 = std::max(0, y - kCutHalfHeight), y1 = std::min(along_size - 1, y + kCutHalfHeight);
  std::vector<float> row(x1 - x0 + 3, 0.0f);
  for (int yy = y0; yy <= y1; ++yy) {
    if (transposed) {
      for (int x = x0 - 1; x <= x1 + 1; ++x) row[x - x0 + 1] += grey.at<uchar>(x, yy);
    } else {
      const uchar* in = grey.ptr<uchar>(yy);
      for (int x = x0 - 1; x <= x1 + 1; ++x) row[x - x0 + 1] += in[x];
    }
  }
  const float norm = 1.0f / static_cast<float>(y1 - y0 + 1);
  std::vector<float> d(x1 - x0 + 1);
  for (int x = x0; x <= x1; ++x) d[x - x0] = sign * 0.5f * (row[x - x0 + 2] - row[x - x0]) * norm;
  int peak = static_cast<int>(std::max_element(d.begin(), d.end()) - d.begin());
  if (d[peak] <= 0) return false;
  if (gap_side != 0) {
    // The first local maximum from the gap's side that is strong enough.
    const int n = static_cast<int>(d.size());
    const float strong = kFirstOfStrongest * d[peak];
    for (int k = 0; k < n; ++k) {
      const int x = gap_side < 0 ? k : n - 1 - k;
      const bool local_max = (x == 0 || d[x] >= d[x - 1]) && (x + 1 == n || d[x] >= d[x + 1]);
      if (d[x] >= strong && local_max) {
        peak = x;
        break;
      }
    }
  }
  double offset = 0;
  if (peak > 0 && peak + 1 < static_cast<int>(d.size())) {
    const double l = d[peak - 1], c = d[peak], r = d[peak + 1];
    const double denom = l - 2 * c + r;
    if (denom < 0) offset = std::clamp(0.5 * (l - r) / denom, -0.5, 0.5);
  }
  out->along = y;
  out->across = x0 + peak + offset;
  out->gradient = d[peak];
  return true;
}

// Line x = a + b y through the transitions, iteratively dropping those off it.
EdgeFit RobustLine(const std::vector<Transition>& points, const EdgeSearch& search, int cuts, int sign) {
  EdgeFit fit;
  fit.cuts = cuts;
  fit.sign = sign;
  if (static_cast<int>(points.size()) < kMinInliers) return fit;
  double b = std::clamp(search.expected.b, -search.max_slope, search.max_slope);
  std::vector<double> offsets;
  for (const Transition& p : points) offsets.push_back(p.across - b * p.along);
  double a = Median(offsets);
  std::vector<bool> inlier(points.size());
  double threshold = 3.0;
  for (int iteration = 0; iteration < 6; ++iteration) {
    std::vector<double> residuals;
    for (size_t i = 0; i < points.size(); ++i) {
      const double r = points[i].across - (a + b * points[i].along);
      inlier[i] = std::abs(r) <= threshold;
      if (inlier[i]) residuals.push_back(std::abs(r));
    }
    if (static_cast<int>(residuals.size()) < kMinInliers) return fit;
    // Weighted least squares over the inliers (weight: transition strength).
    double sw = 0, sy = 0, sx = 0, syy = 0, sxy = 0;
    for (size_t i = 0; i < points.size(); ++i) {
      if (!inlier[i]) continue;
      const double w = points[i].gradient, y = points[i].along, x = points[i].across;
      sw += w;
      sy += w * y;
      sx += w * x;
      syy += w * y * y;
      sxy += w * x * y;
    }
    const double det = sw * syy - sy * sy;
    if (det > 1e-9 * sw * sw) {
      b = std::clamp((sw * sxy - sy * sx) / det, -search.max_slope, search.max_slope);
      a = (sx - b * sy) / sw;
    } else {
      a = sx / sw;
    }
    threshold = std::clamp(3.0 * 1.4826 * Median(residuals), 0.75, 3.0);
  }
  std::vector<double> strengths;
  double sum_sq = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    const double r = points[i].across - (a + b * points[i].along);
    if (std::abs(r) > threshold) continue;
    ++fit.inliers;
    sum_sq += r * r;
    strengths.push_back(points[i].gradient);
  }
  fit.line = {a, b};
  fit.rms_px = fit.inliers > 0 ? std::sqrt(sum_sq / fit.inliers) : 0;
  fit.contrast = Median(strengths);
  fit.found = fit.inliers >= kMinInliers && fit.InlierFraction() >= kMinInlierFraction;
  return fit;
}

EdgeFit FitWithSign(const cv::Mat& grey, const EdgeSearch& search, int sign) {
  const double length = search.along_end - search.along_begin;
  const double step = std::max(1.0, length / kMaxCuts);
  std::vector<Transition> points;
  int cuts = 0;
  const int along_size = search.transposed ? grey.cols : grey.rows;
  for (double yf = search.along_begin; yf <= search.along_end; yf += step) {
    const int y = static_cast<int>(std::lround(yf));
    if (y < 0 || y >= along_size) continue;
    ++cuts;
    const double x = search.expected.XAt(y);
    Transition t;
    if (StrongestTransition(
            grey, search.transposed, y, x - search.behind_px, x + search.ahead_px, sign, search.gap_side, &t)) {
      points.push_back(t);
    }
  }
  EdgeFit fit = RobustLine(points, search, cuts, sign);
  if (!fit.found) return fit;
  // Second pass close to the line: cuts where content outshone the edge further out now find it.
  EdgeSearch narrow = search;
  narrow.expected = fit.line;
  narrow.behind_px = narrow.ahead_px = 2.5;
  points.clear();
  for (double yf = search.along_begin; yf <= search.along_end; yf += step) {
    const int y = static_cast<int>(std::lround(yf));
    if (y < 0 || y >= along_size) continue;
    const double x = narrow.expected.XAt(y);
    Transition t;
    if (StrongestTransition(
            grey, search.transposed, y, x - narrow.behind_px, x + narrow.ahead_px, sign, narrow.gap_side, &t)) {
      points.push_back(t);
    }
  }
  EdgeFit refined = RobustLine(points, narrow, cuts, sign);
  return refined.found ? refined : fit;
}

}  // namespace

EdgeFit FitEdge(const cv::Mat& grey, const EdgeSearch& search) {
  if (search.sign != 0) return FitWithSign(grey, search, search.sign);
  const EdgeFit rising = FitWithSign(grey, search, +1);
  const EdgeFit falling = FitWithSign(grey, search, -1);
  if (rising.found != falling.found) return rising.found ? rising : falling;
  // Both (or neither): the edge more of the cuts agree on, then the stronger.
  const double score_rising = rising.inliers * rising.contrast, score_falling = falling.inliers * falling.contrast;
  return score_rising >= score_falling ? rising : falling;
}

}  // namespace px::lattice
