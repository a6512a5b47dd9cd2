// The IoU matching on boxes with known overlaps (always runs; no data needed).
#include "eval/faces/face_matching.h"

#include <gtest/gtest.h>

namespace px::eval {
namespace {

TEST(FaceMatchingTest, CountsHitsMissesAndFalseFacesAtTheThreshold) {
  const std::vector<cv::Rect2d> truth = {{0, 0, 10, 10}, {100, 100, 20, 20}, {200, 0, 10, 10}};
  // Shifted by 2 px: IoU 80/120 = 0.667 (hit); 20 px box shifted by 5 px both ways: IoU 225/575 =
  // 0.391 (miss at 0.5); one far away.
  const std::vector<cv::Rect2d> detections = {{2, 0, 10, 10}, {105, 105, 20, 20}, {500, 500, 10, 10}};
  const FaceMatch match = MatchFaces(truth, detections, 0.5);
  EXPECT_EQ(match.truth, 3);
  EXPECT_EQ(match.detections, 3);
  EXPECT_EQ(match.true_positives, 1);
  EXPECT_EQ(match.FalsePositives(), 2);
  EXPECT_EQ(match.Misses(), 2);
  ASSERT_EQ(match.matched_iou.size(), 1u);
  EXPECT_NEAR(match.matched_iou[0], 80.0 / 120.0, 1e-9);
  EXPECT_NEAR(match.Precision(), 1.0 / 3, 1e-9);
  EXPECT_NEAR(match.Recall(), 1.0 / 3, 1e-9);
  // At 0.3 the shifted 20 px box counts too.
  EXPECT_EQ(MatchFaces(truth, detections, 0.3).true_positives, 2);
}

TEST(FaceMatchingTest, EachTruthAndDetectionCountsOnceBestOverlapFirst) {
  const std::vector<cv::Rect2d> truth = {{0, 0, 10, 10}};
  // Two detections on one face: the better one is the hit, the other a false face.
  const std::vector<cv::Rect2d> detections = {{1, 0, 10, 10}, {0, 0, 10, 10}};
  const FaceMatch match = MatchFaces(truth, detections);
  EXPECT_EQ(match.true_positives, 1);
  EXPECT_EQ(match.FalsePositives(), 1);
  ASSERT_EQ(match.matched_iou.size(), 1u);
  EXPECT_DOUBLE_EQ(match.matched_iou[0], 1.0);
  // One detection between two faces matches at most one of them.
  const std::vector<cv::Rect2d> two = {{0, 0, 10, 10}, {1, 0, 10, 10}};
  const FaceMatch shared = MatchFaces(two, {{0, 0, 10, 10}});
  EXPECT_EQ(shared.true_positives, 1);
  EXPECT_EQ(shared.Misses(), 1);
}

TEST(FaceMatchingTest, IgnoredBoxesNeitherHitNorFalseAndEmptyCasesAreDefined) {
  const FaceMatch match = MatchFaces({{0, 0, 10, 10}}, {{0, 0, 10, 10}, {50, 50, 10, 10}}, 0.5, {{50, 50, 10, 10}});
  EXPECT_EQ(match.detections, 1);
  EXPECT_EQ(match.true_positives, 1);
  const FaceMatch none = MatchFaces({}, {});
  EXPECT_DOUBLE_EQ(none.Precision(), 1.0);
  EXPECT_DOUBLE_EQ(none.Recall(), 1.0);
  FaceMatch sum = match;
  sum.Add(MatchFaces({{0, 0, 10, 10}}, {}));
  EXPECT_EQ(sum.truth, 2);
  EXPECT_DOUBLE_EQ(sum.Recall(), 0.5);
}

}  // namespace
}  // namespace px::eval
