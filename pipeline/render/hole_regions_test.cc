#include "pipeline/render/hole_regions.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <random>

#include "pipeline/render/hole_fill.h"

namespace px::render {
namespace {

// A 160x120 coverage (255 covered) with holes: strips along the left and right borders, a few
// blobs, scattered single pixels and a hole in the bottom-left corner.
cv::Mat FrameWithHoles(uint32_t seed) {
  cv::Mat coverage(120, 160, CV_8U, cv::Scalar(255));
  std::mt19937 random(seed);
  coverage.colRange(0, 3).setTo(0);
  coverage(cv::Rect(150, 20, 10, 60)).setTo(0);
  for (int i = 0; i < 4; ++i) {
    const cv::Point centre(20 + static_cast<int>(random() % 120), 10 + static_cast<int>(random() % 100));
    cv::circle(coverage, centre, 2 + static_cast<int>(random() % 6), cv::Scalar(0), cv::FILLED);
  }
  for (int i = 0; i < 30; ++i) coverage.at<uint8_t>(random() % 120, random() % 160) = 0;
  coverage(cv::Rect(0, 110, 12, 10)).setTo(0);
  return coverage;
}

// Colour and depth that vary, so a fill reading a wrong window would show.
void Scene(const cv::Mat& coverage, cv::Mat* colour, cv::Mat* depth) {
  *colour = cv::Mat(coverage.size(), CV_32FC3);
  *depth = cv::Mat(coverage.size(), CV_32F);
  for (int y = 0; y < coverage.rows; ++y) {
    for (int x = 0; x < coverage.cols; ++x) {
      const bool known = coverage.at<uint8_t>(y, x) != 0;
      colour->at<cv::Vec3f>(y, x) = known ? cv::Vec3f(x, y, (x * 7 + y * 3) % 255) : cv::Vec3f(0, 0, 0);
      depth->at<float>(y, x) = known ? 1.0f + ((x / 9 + y / 7) % 3) : 0.0f;
    }
  }
}

TEST(HoleRegionsTest, CoverEveryHoleAndNoOtherBoxesHoles) {
  for (uint32_t seed = 1; seed <= 20; ++seed) {
    const cv::Mat coverage = FrameWithHoles(seed);
    const int margin = 3;
    const std::vector<cv::Rect> regions = HoleRegions(coverage, margin);
    ASSERT_FALSE(regions.empty());
    cv::Mat owner(coverage.size(), CV_32S, cv::Scalar(-1));
    for (size_t i = 0; i < regions.size(); ++i) {
      EXPECT_EQ(regions[i] & cv::Rect(0, 0, coverage.cols, coverage.rows), regions[i]);
      for (int y = regions[i].y; y < regions[i].br().y; ++y) {
        for (int x = regions[i].x; x < regions[i].br().x; ++x) {
          if (coverage.at<uint8_t>(y, x) != 0) continue;
          EXPECT_EQ(owner.at<int>(y, x), -1) << "hole (" << x << ", " << y << ") in two boxes, seed " << seed;
          owner.at<int>(y, x) = static_cast<int>(i);
        }
      }
    }
    EXPECT_EQ(cv::countNonZero((owner == -1) & (coverage == 0)), 0) << "a hole outside every box, seed " << seed;
  }
}

TEST(HoleRegionsTest, HoleScoreAndFillingBoxByBoxEqualTheWholeFrame) {
  const SoftZ soft_z(2.0, 0.1);
  for (uint32_t seed = 1; seed <= 10; ++seed) {
    const cv::Mat coverage = FrameWithHoles(seed);
    const double total = static_cast<double>(coverage.total());
    const std::vector<cv::Rect> regions = HoleRegions(coverage, 3);
    double score = 0;
    for (const cv::Rect& r : regions) score += HoleScore(coverage(r)) * r.area() / total;
    EXPECT_NEAR(score, HoleScore(coverage), 1e-9 * HoleScore(coverage)) << "seed " << seed;

    cv::Mat colour, depth, known = coverage.clone();
    Scene(coverage, &colour, &depth);
    cv::Mat box_colour = colour.clone(), box_depth = depth.clone();
    FillHolesReverseSoftZ(soft_z, 3, 0, &known, &colour, &depth);
    for (const cv::Rect& r : regions) {
      cv::Mat box_known = coverage(r).clone(), c = box_colour(r), d = box_depth(r);
      FillHolesReverseSoftZ(soft_z, 3, 0, &box_known, &c, &d);
    }
    EXPECT_EQ(cv::norm(colour, box_colour, cv::NORM_INF), 0.0) << "seed " << seed;
    EXPECT_EQ(cv::norm(depth, box_depth, cv::NORM_INF), 0.0) << "seed " << seed;
  }
}

TEST(HoleRegionsTest, NoHolesNoBoxesAndAllHolesTheWholeFrame) {
  EXPECT_TRUE(HoleRegions(cv::Mat(20, 30, CV_8U, cv::Scalar(255)), 2).empty());
  const std::vector<cv::Rect> all = HoleRegions(cv::Mat(20, 30, CV_8U, cv::Scalar(0)), 2);
  ASSERT_EQ(all.size(), 1u);
  EXPECT_EQ(all[0], cv::Rect(0, 0, 30, 20));
}

}  // namespace
}  // namespace px::render
