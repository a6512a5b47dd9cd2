#include "pipeline/calib/tracks.h"

#include <algorithm>
#include <numeric>

#include "pipeline/core/disjoint_sets.h"

namespace px::calib {

std::vector<Track> BuildTracks(const std::vector<int>& features_per_view,
                               const std::vector<PairMatches>& pairs,
                               int min_length) {
  std::vector<int> offset(features_per_view.size() + 1, 0);
  for (size_t v = 0; v < features_per_view.size(); ++v) offset[v + 1] = offset[v] + features_per_view[v];
  const int total = offset.back();
  DisjointSets sets(total);
  std::vector<char> matched(total, 0);
  const int num_views = static_cast<int>(features_per_view.size());
  for (const PairMatches& pair : pairs) {
    if (pair.view_a < 0 || pair.view_b < 0 || pair.view_a >= num_views || pair.view_b >= num_views) continue;
    for (const FeatureMatch& match : pair.matches) {
      if (match.a < 0 || match.b < 0 || match.a >= features_per_view[pair.view_a] ||
          match.b >= features_per_view[pair.view_b]) {
        continue;
      }
      const int a = offset[pair.view_a] + match.a, b = offset[pair.view_b] + match.b;
      sets.Join(a, b);
      matched[a] = matched[b] = 1;
    }
  }
  // Group nodes by root; nodes are visited in (view, feature) order, so tracks come out sorted.
  std::vector<int> track_of_root(total, -1);
  std::vector<Track> tracks;
  for (int v = 0; v < num_views; ++v) {
    for (int f = 0; f < features_per_view[v]; ++f) {
      const int node = offset[v] + f;
      if (!matched[node]) continue;
      const int root = sets.Find(node);
      if (track_of_root[root] < 0) {
        track_of_root[root] = static_cast<int>(tracks.size());
        tracks.emplace_back();
      }
      tracks[track_of_root[root]].observations.push_back({v, f});
    }
  }
  std::vector<Track> kept;
  for (Track& track : tracks) {
    bool conflict = false;
    for (size_t i = 1; i < track.observations.size(); ++i) {
      conflict |= track.observations[i].view == track.observations[i - 1].view;
    }
    if (!conflict && static_cast<int>(track.observations.size()) >= min_length) kept.push_back(std::move(track));
  }
  return kept;
}

}  // namespace px::calib
