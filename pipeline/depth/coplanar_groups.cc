#include "pipeline/depth/coplanar_groups.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <deque>
#include <numeric>

#include "pipeline/core/check.h"

namespace px::depth {
namespace {

using Sample = PlaneSample;

// Normal equations of the weighted least-squares plane u = a x + b y + c, grown sample by sample.
class PlaneAccumulator {
 public:
  void Add(const Sample& s) {
    const Eigen::Vector3d row(s.x, s.y, 1.0);
    ata_ += s.w * row * row.transpose();
    atb_ += s.w * s.u * row;
  }
  // False when the samples do not pin a plane down (too few, or all on a line).
  bool Solve(InversePlane* plane) const {
    const Eigen::FullPivLU<Eigen::Matrix3d> lu(ata_);
    if (lu.rank() < 3) return false;
    const Eigen::Vector3d solution = lu.solve(atb_);
    if (!solution.allFinite()) return false;
    plane->a = solution(0);
    plane->b = solution(1);
    plane->c = solution(2);
    return true;
  }

 private:
  Eigen::Matrix3d ata_ = Eigen::Matrix3d::Zero();
  Eigen::Vector3d atb_ = Eigen::Vector3d::Zero();
};

double KeptWeight(const std::vector<Sample>& samples, const InversePlane& plane, double tolerance) {
  double kept = 0;
  for (const Sample& s : samples) {
    if (std::abs(s.u - plane.At(s.x, s.y)) <= tolerance) kept += s.w;
  }
  return kept;
}

void AddInliers(const std::vector<Sample>& samples,
                const InversePlane& plane,
                double tolerance,
                PlaneAccumulator* accumulator) {
  for (const Sample& s : samples) {
    if (std::abs(s.u - plane.At(s.x, s.y)) <= tolerance) accumulator->Add(s);
  }
}

}  // namespace

CoplanarGroups MergeCoplanarSegments(const Superpixels& segments,
                                     const std::vector<std::vector<int>>& pixels,
                                     const cv::Mat& inverse_depth,
                                     const cv::Mat& weight,
                                     const CoplanarGroupOptions& options,
                                     std::vector<SegmentPlane>* planes) {
  PX_CHECK(inverse_depth.type() == CV_32F && weight.type() == CV_32F &&
           inverse_depth.size() == segments.labels.size() && weight.size() == segments.labels.size());
  PX_CHECK(options.tolerance > 0 && options.keep_fraction > 0 && options.keep_fraction <= 1);
  PX_CHECK(planes->size() == static_cast<size_t>(segments.count) && pixels.size() == planes->size());
  const int n = segments.count;
  const double tolerance = options.tolerance;

  // Each fitted segment's confident pixels, and the weight its own plane keeps of them.
  std::vector<std::vector<Sample>> samples(n);
  std::vector<double> own_kept(n, 0.0);
  std::vector<char> eligible(n, 0);
  for (int s = 0; s < n; ++s) {
    const SegmentPlane& plane = (*planes)[s];
    const bool fitted = plane.source == PlaneSource::kFitted || plane.source == PlaneSource::kFronto;
    if (!fitted || plane.support < options.min_support) continue;
    ConfidentSamples(pixels[s], inverse_depth, weight, options.min_weight, &samples[s]);
    own_kept[s] = KeptWeight(samples[s], plane.plane, tolerance);
    eligible[s] = own_kept[s] > 0;
  }

  // Seeds: the segments whose own planes hold the most weight first.
  std::vector<int> order;
  for (int s = 0; s < n; ++s) {
    if (eligible[s]) order.push_back(s);
  }
  std::stable_sort(order.begin(), order.end(), [&](int l, int r) { return own_kept[l] > own_kept[r]; });

  CoplanarGroups result;
  result.group_of.assign(n, -1);
  std::vector<int> claimed_by(n, -1);  // the group a segment joined while groups grew
  std::vector<int> tested_by(n, -1);   // the last group that tested the segment (each tests it once)
  int next_group = 0;
  for (int seed : order) {
    if (claimed_by[seed] != -1) continue;
    const int group = next_group++;
    claimed_by[seed] = group;
    tested_by[seed] = group;
    std::vector<int> members = {seed};
    PlaneAccumulator accumulator;
    AddInliers(samples[seed], (*planes)[seed].plane, tolerance, &accumulator);
    InversePlane group_plane = (*planes)[seed].plane;
    std::deque<int> frontier(segments.adjacent[seed].begin(), segments.adjacent[seed].end());
    while (!frontier.empty()) {
      const int t = frontier.front();
      frontier.pop_front();
      if (!eligible[t] || claimed_by[t] != -1 || tested_by[t] == group) continue;
      tested_by[t] = group;
      if (KeptWeight(samples[t], group_plane, tolerance) < options.keep_fraction * own_kept[t]) continue;
      claimed_by[t] = group;
      members.push_back(t);
      AddInliers(samples[t], group_plane, tolerance, &accumulator);
      InversePlane refit;
      if (accumulator.Solve(&refit)) group_plane = refit;
      frontier.insert(frontier.end(), segments.adjacent[t].begin(), segments.adjacent[t].end());
    }
    if (members.size() < 2) continue;

    // The plane moved as the group grew: members it no longer explains keep their own planes,
    // and the rest are fitted once more without them.
    PlaneAccumulator final_accumulator;
    std::vector<int> kept_members;
    for (int m : members) {
      if (KeptWeight(samples[m], group_plane, tolerance) >= options.keep_fraction * own_kept[m]) {
        kept_members.push_back(m);
        AddInliers(samples[m], group_plane, tolerance, &final_accumulator);
      }
    }
    InversePlane final_plane;
    if (kept_members.size() < 2 || !final_accumulator.Solve(&final_plane)) continue;
    for (int m : kept_members) {
      (*planes)[m].plane = final_plane;
      (*planes)[m].source = PlaneSource::kFitted;
      result.group_of[m] = result.groups;
    }
    ++result.groups;
    result.grouped_segments += static_cast<int>(kept_members.size());
  }
  return result;
}

}  // namespace px::depth
