#include "pipeline/render/seam_planes.h"

#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <utility>
#include <vector>

namespace px::render {
namespace {

// A segment's plane about its pixels' centroid: 1/z = a (x - cx) + b (y - cy) + c (well
// conditioned for the joint fit: a, b and c then hardly couple).
struct Centred {
  double cx = 0, cy = 0;
  Eigen::Vector3d Row(double x, double y) const { return Eigen::Vector3d(x - cx, y - cy, 1.0); }
};

// True when the plane keeps a positive inverse depth at the corners of the segment's rectangle
// (its bbox grown by one pixel centre, as the renderer draws it).
bool PositiveOverRectangle(const DepthSegment& s) {
  const cv::Rect& b = s.bbox;
  for (const double x : {b.x - 1.0, static_cast<double>(b.x + b.width)}) {
    for (const double y : {b.y - 1.0, static_cast<double>(b.y + b.height)}) {
      if (!(s.InverseDepthAt(x, y) > 1e-6)) return false;
    }
  }
  return true;
}

}  // namespace

LayeredDepthView WithSeamPlanes(const LayeredDepthView& view,
                                const SeamPlaneOptions& options,
                                SeamPlaneReport* report) {
  if (report != nullptr) *report = SeamPlaneReport();
  if (!(options.seam_weight > 0)) return view;
  const int width = view.camera.width, height = view.camera.height;
  const SegmentLayer& front = view.layers[0];
  const SegmentLayer& back = view.layers[1];
  const auto sized = [&](const cv::Mat& m, int type) {
    return m.type() == type && m.cols == width && m.rows == height;
  };
  if (!sized(front.weight, CV_32F) || !sized(front.segment, CV_32S) || !sized(back.weight, CV_32F) ||
      !sized(back.segment, CV_32S)) {
    return view;  // the renderer's own checks name what is wrong
  }
  const int n = view.NumSegments();
  const auto valid = [&](int32_t s) {
    return s >= 0 && s < n && std::isfinite(view.segments[s].inv_depth_a) &&
           std::isfinite(view.segments[s].inv_depth_b) && std::isfinite(view.segments[s].inv_depth_c);
  };
  // Pure pixels (one segment, fully) are a segment's own; they set its centroid and its data term.
  const auto pure = [&](int x, int y) {
    return valid(front.segment.at<int32_t>(y, x)) && front.weight.at<float>(y, x) >= 1.0f &&
           back.segment.at<int32_t>(y, x) == SegmentLayer::kNoSegment && back.weight.at<float>(y, x) == 0;
  };
  std::vector<Centred> centred(n);
  std::vector<double> count(n, 0);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      if (!pure(x, y)) continue;
      const int32_t s = front.segment.at<int32_t>(y, x);
      centred[s].cx += x;
      centred[s].cy += y;
      ++count[s];
    }
  }
  for (int s = 0; s < n; ++s) {
    if (count[s] > 0) centred[s].cx /= count[s], centred[s].cy /= count[s];
  }
  // Normal equations of sum over own pixels of (plane - own plane)^2 plus seam_weight times sum
  // over seam pixel pairs of (plane_A - plane_B)^2 at the pair's midpoint.
  std::vector<Eigen::Matrix3d> data(n, Eigen::Matrix3d::Zero());      // own pixels and seams
  std::vector<Eigen::Matrix3d> own_data(n, Eigen::Matrix3d::Zero());  // own pixels
  std::vector<Eigen::Vector3d> own(n, Eigen::Vector3d::Zero());       // the own plane in centred form
  for (int s = 0; s < n; ++s) {
    if (!valid(s)) continue;
    const DepthSegment& d = view.segments[s];
    own[s] = Eigen::Vector3d(d.inv_depth_a, d.inv_depth_b, d.InverseDepthAt(centred[s].cx, centred[s].cy));
  }
  std::map<std::pair<int32_t, int32_t>, Eigen::Matrix3d> coupling;  // off-diagonal blocks of the seams
  std::vector<bool> joined(n, false);
  int pairs = 0;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      if (!pure(x, y)) continue;
      const int32_t a = front.segment.at<int32_t>(y, x);
      const Eigen::Vector3d row = centred[a].Row(x, y);
      data[a] += row * row.transpose();
      own_data[a] += row * row.transpose();
      for (const auto& [dx, dy] : std::array<std::array<int, 2>, 2>{{{1, 0}, {0, 1}}}) {
        const int qx = x + dx, qy = y + dy;
        if (qx >= width || qy >= height || !pure(qx, qy)) continue;
        const int32_t b = front.segment.at<int32_t>(qy, qx);
        if (b == a) continue;
        const double mx = x + 0.5 * dx, my = y + 0.5 * dy;
        const double ia = view.segments[a].InverseDepthAt(mx, my), ib = view.segments[b].InverseDepthAt(mx, my);
        if (!(ia > 0 && ib > 0) || std::abs(ia - ib) >= options.max_step * ia) continue;  // a depth edge
        // Keyed by the lower index first: the block of rows `lo`, columns `hi`.
        const int32_t lo = std::min(a, b), hi = std::max(a, b);
        const Eigen::Vector3d rl = centred[lo].Row(mx, my), rh = centred[hi].Row(mx, my);
        data[lo] += options.seam_weight * rl * rl.transpose();
        data[hi] += options.seam_weight * rh * rh.transpose();
        coupling.try_emplace({lo, hi}, Eigen::Matrix3d::Zero()).first->second -=
            options.seam_weight * rl * rh.transpose();
        joined[a] = joined[b] = true;
        ++pairs;
      }
    }
  }
  if (pairs == 0) return view;
  // A small pull of every plane towards its own keeps segments without pure pixels determined.
  constexpr double kAnchor = 1e-3;
  std::vector<Eigen::Triplet<double>> terms;
  terms.reserve(9 * (n + 2 * coupling.size()));
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(3 * n);
  for (int s = 0; s < n; ++s) {
    // The right-hand side is the own-fit part only (own pixels and the anchor), the seam terms
    // being differences between planes.
    rhs.segment<3>(3 * s) = (own_data[s] + kAnchor * Eigen::Matrix3d::Identity()) * own[s];
    const Eigen::Matrix3d m = data[s] + kAnchor * Eigen::Matrix3d::Identity();
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) terms.emplace_back(3 * s + i, 3 * s + j, m(i, j));
    }
  }
  for (const auto& [key, block] : coupling) {
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        terms.emplace_back(3 * key.first + i, 3 * key.second + j, block(i, j));
        terms.emplace_back(3 * key.second + j, 3 * key.first + i, block(i, j));
      }
    }
  }
  Eigen::SparseMatrix<double> normal(3 * n, 3 * n);
  normal.setFromTriplets(terms.begin(), terms.end());
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(normal);
  if (solver.info() != Eigen::Success) return view;
  const Eigen::VectorXd planes = solver.solve(rhs);
  if (solver.info() != Eigen::Success || !planes.allFinite()) return view;
  LayeredDepthView out = view;
  int changed = 0;
  for (int s = 0; s < n; ++s) {
    if (!joined[s]) continue;
    DepthSegment fitted = out.segments[s];
    const Eigen::Vector3d p = planes.segment<3>(3 * s);
    fitted.inv_depth_a = p[0];
    fitted.inv_depth_b = p[1];
    fitted.inv_depth_c = p[2] - p[0] * centred[s].cx - p[1] * centred[s].cy;
    if (!PositiveOverRectangle(fitted)) continue;
    out.segments[s] = fitted;
    ++changed;
  }
  // The per-pixel depth follows its dominant layer's plane (layered_depth.h), where that changed.
  if (changed > 0 && out.depth_m.type() == CV_32F && out.depth_m.size() == cv::Size(width, height)) {
    out.depth_m = view.depth_m.clone();
    for (int y = 0; y < height; ++y) {
      float* z = out.depth_m.ptr<float>(y);
      for (int x = 0; x < width; ++x) {
        const int layer = front.weight.at<float>(y, x) >= 0.5f ? 0 : 1;
        const int32_t segment = view.layers[layer].segment.at<int32_t>(y, x);
        if (!(z[x] > 0) || segment < 0 || segment >= n || !joined[segment]) continue;
        const double inverse = out.segments[segment].InverseDepthAt(x, y);
        if (inverse > 0) z[x] = static_cast<float>(1.0 / inverse);
      }
    }
  }
  if (report != nullptr) {
    report->seam_pairs = pairs;
    report->planes_changed = changed;
  }
  return out;
}

}  // namespace px::render
