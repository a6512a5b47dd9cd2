// Tracks: one scene point's features across views, joined from pairwise matches (union-find).
#pragma once

#include <vector>

#include "pipeline/calib/matching.h"

namespace px::calib {

struct TrackObservation {
  int view = -1;
  int feature = -1;
};

struct Track {
  std::vector<TrackObservation> observations;  // sorted by view, at most one per view
};

struct PairMatches {
  int view_a = -1;
  int view_b = -1;
  std::vector<FeatureMatch> matches;  // verified (geometric inliers)
};

// Joins matches into tracks. features_per_view[v] is view v's feature count. A track that would
// hold two features of one view (conflicting matches) is dropped: it cannot be one point.
// Tracks shorter than `min_length` views are dropped too. Deterministic order (by first view,
// then feature).
std::vector<Track> BuildTracks(const std::vector<int>& features_per_view,
                               const std::vector<PairMatches>& pairs,
                               int min_length = 2);

}  // namespace px::calib
