#include "pipeline/calib/matching.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <string>

namespace px::calib {
namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();

float DescriptorDistance(const cv::Mat& a, int i, const cv::Mat& b, int j) {
  if (a.type() == CV_8U) {
    return static_cast<float>(cv::norm(a.row(i), b.row(j), cv::NORM_HAMMING));
  }
  const float* x = a.ptr<float>(i);
  const float* y = b.ptr<float>(j);
  float sum = 0;
  for (int k = 0; k < a.cols; ++k) {
    const float d = x[k] - y[k];
    sum += d * d;
  }
  return std::sqrt(sum);
}

struct Best {
  int index = -1;
  float first = kInfinity;
  float second = kInfinity;
  void Offer(int candidate, float distance) {
    if (distance < first) {
      second = first;
      first = distance;
      index = candidate;
    } else if (distance < second) {
      second = distance;
    }
  }
  bool PassesRatio(double ratio) const { return index >= 0 && (second == kInfinity || first < ratio * second); }
};

// Float descriptors (SIFT): every distance from one matrix product per block of `a`'s rows, as
// |x|^2 + |y|^2 - 2 x.y, each feature's best two (a) and best one (b) kept as the blocks go. A
// pair of 2000-feature images takes a tenth of what a brute-force matcher's pair-by-pair
// distances and second pass for the mutual test took.
std::vector<FeatureMatch> MatchAllFloat(const Features& a, const Features& b, const MatchOptions& options) {
  constexpr int kBlockRows = 512;  // a block's distances: 512 x |b| floats
  cv::Mat squares_a, squares_b;
  cv::reduce(a.descriptors.mul(a.descriptors), squares_a, 1, cv::REDUCE_SUM, CV_32F);
  cv::reduce(b.descriptors.mul(b.descriptors), squares_b, 1, cv::REDUCE_SUM, CV_32F);
  std::vector<Best> best_of_a(a.size());
  std::vector<Best> best_of_b(b.size());
  cv::Mat dots;
  for (int start = 0; start < a.size(); start += kBlockRows) {
    const int end = std::min(a.size(), start + kBlockRows);
    cv::gemm(a.descriptors.rowRange(start, end), b.descriptors, 1.0, cv::noArray(), 0.0, dots, cv::GEMM_2_T);
    for (int i = start; i < end; ++i) {
      const float* dot = dots.ptr<float>(i - start);
      const float square_a = squares_a.at<float>(i);
      Best& best = best_of_a[i];
      for (int j = 0; j < b.size(); ++j) {
        const float distance = std::sqrt(std::max(0.0f, square_a + squares_b.at<float>(j) - 2 * dot[j]));
        best.Offer(j, distance);
        best_of_b[j].Offer(i, distance);
      }
    }
  }
  std::vector<FeatureMatch> matches;
  for (int i = 0; i < a.size(); ++i) {
    const Best& best = best_of_a[i];
    if (!best.PassesRatio(options.ratio)) continue;
    if (options.mutual && best_of_b[best.index].index != i) continue;
    matches.push_back({i, best.index});
  }
  return matches;
}

}  // namespace

Status MatchOptions::Validate() const {
  if (!(ratio > 0 && ratio <= 1)) {
    return InvalidArgumentError("match options: ratio = " + std::to_string(ratio) + " is outside (0, 1]");
  }
  return OkStatus();
}

std::vector<FeatureMatch> MatchAll(const Features& a, const Features& b, const MatchOptions& options) {
  std::vector<FeatureMatch> matches;
  if (a.size() == 0 || b.size() == 0 || a.descriptors.type() != b.descriptors.type()) return matches;
  if (!a.binary()) return MatchAllFloat(a, b, options);
  cv::BFMatcher matcher(cv::NORM_HAMMING);
  std::vector<std::vector<cv::DMatch>> a_to_b, b_to_a;
  matcher.knnMatch(a.descriptors, b.descriptors, a_to_b, 2);
  std::vector<int> best_of_b(b.size(), -1);
  if (options.mutual) {
    matcher.knnMatch(b.descriptors, a.descriptors, b_to_a, 1);
    for (const std::vector<cv::DMatch>& m : b_to_a) {
      if (!m.empty()) best_of_b[m[0].queryIdx] = m[0].trainIdx;
    }
  }
  for (const std::vector<cv::DMatch>& m : a_to_b) {
    if (m.empty()) continue;
    if (m.size() > 1 && !(m[0].distance < options.ratio * m[1].distance)) continue;
    if (options.mutual && best_of_b[m[0].trainIdx] != m[0].queryIdx) continue;
    matches.push_back({m[0].queryIdx, m[0].trainIdx});
  }
  return matches;
}

std::vector<FeatureMatch> MatchCandidates(const Features& a,
                                          const Features& b,
                                          const std::vector<std::vector<int>>& candidates_of_a,
                                          const MatchOptions& options) {
  std::vector<FeatureMatch> matches;
  if (a.size() == 0 || b.size() == 0 || a.descriptors.type() != b.descriptors.type()) return matches;
  std::vector<Best> best_of_a(a.size());
  std::vector<Best> best_of_b(b.size());
  const int n = std::min<int>(a.size(), static_cast<int>(candidates_of_a.size()));
  for (int i = 0; i < n; ++i) {
    for (int j : candidates_of_a[i]) {
      const float distance = DescriptorDistance(a.descriptors, i, b.descriptors, j);
      best_of_a[i].Offer(j, distance);
      best_of_b[j].Offer(i, distance);
    }
  }
  for (int i = 0; i < n; ++i) {
    const Best& best = best_of_a[i];
    if (!best.PassesRatio(options.ratio)) continue;
    if (options.mutual && best_of_b[best.index].index != i) continue;
    matches.push_back({i, best.index});
  }
  return matches;
}

std::vector<std::vector<int>> EpipolarCandidates(const std::vector<Eigen::Vector3d>& rays_a,
                                                 const std::vector<Eigen::Vector2d>& undistorted_px_b,
                                                 const Rigid3& b_from_a,
                                                 const Eigen::Matrix3d& k_b,
                                                 double min_depth,
                                                 double tolerance_px) {
  std::vector<std::vector<int>> candidates(rays_a.size());
  if (undistorted_px_b.empty()) return candidates;
  // Bucket b's points on a grid of cells about the tolerance's size.
  Eigen::Vector2d lo = undistorted_px_b[0], hi = undistorted_px_b[0];
  for (const Eigen::Vector2d& p : undistorted_px_b) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double cell = std::max(4.0, tolerance_px);
  const int cols = static_cast<int>((hi.x() - lo.x()) / cell) + 1;
  const int rows = static_cast<int>((hi.y() - lo.y()) / cell) + 1;
  std::vector<std::vector<int>> grid(static_cast<size_t>(cols) * rows);
  for (int j = 0; j < static_cast<int>(undistorted_px_b.size()); ++j) {
    const Eigen::Vector2d& p = undistorted_px_b[j];
    const int cx = static_cast<int>((p.x() - lo.x()) / cell), cy = static_cast<int>((p.y() - lo.y()) / cell);
    grid[static_cast<size_t>(cy) * cols + cx].push_back(j);
  }
  const Eigen::Matrix3d r = b_from_a.RotationMatrix();
  const Eigen::Vector3d kt = k_b * b_from_a.translation;
  const Eigen::Matrix3d kr = k_b * r;
  for (size_t i = 0; i < rays_a.size(); ++i) {
    // A point at depth d along the ray projects to K (d R x + t): from d = min_depth to infinity
    // (K R x, the vanishing point of the ray) the image moves along a straight segment.
    const Eigen::Vector3d direction = kr * rays_a[i];
    const Eigen::Vector3d near = min_depth * direction + kt;
    if (direction.z() <= 1e-9 || near.z() <= 1e-9) continue;  // the ray leaves b's view
    const Eigen::Vector2d p0 = near.hnormalized();
    const Eigen::Vector2d p1 = direction.hnormalized();
    const Eigen::Vector2d box_lo = p0.cwiseMin(p1).array() - tolerance_px;
    const Eigen::Vector2d box_hi = p0.cwiseMax(p1).array() + tolerance_px;
    // Clamped as doubles first: a ray almost parallel to b's image plane ends far outside.
    const auto cell_index = [&](double value, double origin, int count) {
      return static_cast<int>(std::clamp(std::floor((value - origin) / cell), -1.0, static_cast<double>(count)));
    };
    const int x0 = std::max(0, cell_index(box_lo.x(), lo.x(), cols));
    const int y0 = std::max(0, cell_index(box_lo.y(), lo.y(), rows));
    const int x1 = std::min(cols - 1, cell_index(box_hi.x(), lo.x(), cols));
    const int y1 = std::min(rows - 1, cell_index(box_hi.y(), lo.y(), rows));
    const Eigen::Vector2d segment = p1 - p0;
    const double length2 = segment.squaredNorm();
    for (int gy = y0; gy <= y1; ++gy) {
      for (int gx = x0; gx <= x1; ++gx) {
        for (int j : grid[static_cast<size_t>(gy) * cols + gx]) {
          const Eigen::Vector2d d = undistorted_px_b[j] - p0;
          const double s = length2 > 0 ? std::clamp(d.dot(segment) / length2, 0.0, 1.0) : 0.0;
          if ((d - s * segment).squaredNorm() <= tolerance_px * tolerance_px) candidates[i].push_back(j);
        }
      }
    }
  }
  return candidates;
}

}  // namespace px::calib
