#include "pipeline/depth/weak_regions.h"

#include <algorithm>
#include <map>
#include <tuple>

#include "pipeline/core/check.h"
#include "pipeline/core/disjoint_sets.h"

namespace px::depth {
namespace {

// Planes copied from segment to segment are bit-identical: the key that tells them apart.
using PlaneKey = std::tuple<double, double, double>;
PlaneKey KeyOf(const InversePlane& p) { return {p.a, p.b, p.c}; }

}  // namespace

WeakRegionStats UnifyWeakRegions(const Superpixels& segments,
                                 const PlaneCost& cost,
                                 const WeakRegionOptions& options,
                                 std::vector<SegmentPlane>* planes) {
  const int n = segments.count;
  PX_CHECK(planes->size() == static_cast<size_t>(n));
  const auto weak = [&](int s) { return (*planes)[s].source == PlaneSource::kPropagated; };
  DisjointSets sets(n);
  for (int s = 0; s < n; ++s) {
    if (!weak(s)) continue;
    for (int t : segments.adjacent[s]) {
      if (t > s && weak(t) && cv::norm(segments.mean_lab[s] - segments.mean_lab[t]) < options.same_colour_lab) {
        sets.Join(s, t);
      }
    }
  }
  std::map<int, std::vector<int>> regions;
  for (int s = 0; s < n; ++s) {
    if (weak(s)) regions[sets.Find(s)].push_back(s);
  }

  WeakRegionStats stats;
  for (const auto& region : regions) {
    const std::vector<int>& members = region.second;
    if (static_cast<int>(members.size()) < options.min_segments) continue;
    ++stats.regions;
    // Candidates: the members' planes and their fitted neighbours', by how many hold each.
    std::map<PlaneKey, std::pair<int, InversePlane>> held;
    for (int s : members) {
      auto& entry = held[KeyOf((*planes)[s].plane)];
      ++entry.first;
      entry.second = (*planes)[s].plane;
      for (int t : segments.adjacent[s]) {
        const PlaneSource source = (*planes)[t].source;
        if (source != PlaneSource::kFitted && source != PlaneSource::kFronto) continue;
        auto& neighbour = held[KeyOf((*planes)[t].plane)];
        ++neighbour.first;
        neighbour.second = (*planes)[t].plane;
      }
    }
    std::vector<std::pair<int, InversePlane>> candidates;
    for (const auto& [key, entry] : held) candidates.push_back(entry);
    std::stable_sort(
        candidates.begin(), candidates.end(), [](const auto& l, const auto& r) { return l.first > r.first; });
    if (static_cast<int>(candidates.size()) > options.max_candidates) candidates.resize(options.max_candidates);
    if (candidates.size() < 2) continue;

    // The members' costs along every candidate, and the candidate best over the whole region.
    std::vector<std::vector<double>> member_cost(candidates.size(), std::vector<double>(members.size()));
    int best = -1;
    double best_total = 0;
    for (size_t c = 0; c < candidates.size(); ++c) {
      double total = 0;
      for (size_t m = 0; m < members.size(); ++m) {
        member_cost[c][m] = cost(members[m], candidates[c].second);
        total += member_cost[c][m] * segments.sizes[members[m]];
      }
      if (best < 0 || total < best_total) {
        best = static_cast<int>(c);
        best_total = total;
      }
    }
    const InversePlane& chosen = candidates[best].second;
    for (size_t m = 0; m < members.size(); ++m) {
      SegmentPlane& plane = (*planes)[members[m]];
      if (KeyOf(plane.plane) == KeyOf(chosen)) continue;
      // The member's cost along its own plane: among the candidates' unless that plane was cut.
      const auto own = std::find_if(
          candidates.begin(), candidates.end(), [&](const auto& c) { return KeyOf(c.second) == KeyOf(plane.plane); });
      const double own_cost =
          own != candidates.end() ? member_cost[own - candidates.begin()][m] : cost(members[m], plane.plane);
      if (member_cost[best][m] > own_cost + options.cost_margin) continue;
      plane.plane = chosen;
      ++stats.changed_segments;
    }
  }
  return stats;
}

}  // namespace px::depth
