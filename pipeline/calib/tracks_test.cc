#include "pipeline/calib/tracks.h"

#include <gtest/gtest.h>

namespace px::calib {
namespace {

TEST(TracksTest, JoinsChainsAndDropsConflicts) {
  // View 0 feature 1 <-> view 1 feature 2 <-> view 2 feature 0: one track over three views.
  // View 0 feature 3 matches view 1 features 0 and 1 (via view 2): a conflict, dropped.
  std::vector<PairMatches> pairs = {{0, 1, {{1, 2}, {3, 0}}}, {1, 2, {{2, 0}, {1, 4}}}, {0, 2, {{3, 4}}}};
  const std::vector<Track> tracks = BuildTracks({5, 5, 5}, pairs);
  ASSERT_EQ(tracks.size(), 1u);
  ASSERT_EQ(tracks[0].observations.size(), 3u);
  EXPECT_EQ(tracks[0].observations[0].view, 0);
  EXPECT_EQ(tracks[0].observations[0].feature, 1);
  EXPECT_EQ(tracks[0].observations[1].view, 1);
  EXPECT_EQ(tracks[0].observations[1].feature, 2);
  EXPECT_EQ(tracks[0].observations[2].view, 2);
  EXPECT_EQ(tracks[0].observations[2].feature, 0);
  EXPECT_TRUE(BuildTracks({5, 5, 5}, pairs, 4).empty());
}

TEST(TracksTest, IgnoresMatchesOutsideTheViews) {
  std::vector<PairMatches> pairs = {{0, 1, {{7, 0}, {0, 0}}}, {0, 5, {{0, 0}}}};
  const std::vector<Track> tracks = BuildTracks({2, 2}, pairs);
  ASSERT_EQ(tracks.size(), 1u);
  EXPECT_EQ(tracks[0].observations.size(), 2u);
}

}  // namespace
}  // namespace px::calib
