// Coplanar groups: segments on one noisy plane share a plane closer to the truth than their
// own fits, a depth step and a curved surface stop a group, and unfitted segments stay out.
#include "pipeline/depth/coplanar_groups.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <opencv2/core.hpp>
#include <set>
#include <vector>

#include "pipeline/depth/plane_scene_test_util.h"

namespace px::depth {
namespace {

constexpr int kCols = 96, kRows = 64, kBlockPx = 8;
constexpr double kTolerance = 0.02;
constexpr double kNoise = 0.006;

// Inverse depth from `truth` plus Gaussian noise, every pixel of full weight.
cv::Mat NoisyInverseDepth(const std::function<double(double, double)>& truth, uint64_t seed) {
  cv::Mat noise(kRows, kCols, CV_32F);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, kNoise);
  cv::Mat u(kRows, kCols, CV_32F);
  for (int y = 0; y < kRows; ++y) {
    for (int x = 0; x < kCols; ++x) u.at<float>(y, x) = static_cast<float>(truth(x, y)) + noise.at<float>(y, x);
  }
  return u;
}

PlaneFitOptions FitOptions() {
  PlaneFitOptions options;
  options.inlier_tolerance = kTolerance;
  return options;
}

CoplanarGroupOptions GroupOptions() {
  CoplanarGroupOptions options;
  options.tolerance = kTolerance;
  return options;
}

// The largest and the mean error of the segments' planes at their centres.
struct CentreErrors {
  double worst = 0, mean = 0;
};
CentreErrors CentreError(const std::vector<SegmentPlane>& planes,
                         const Superpixels& segments,
                         const std::function<double(double, double)>& truth) {
  CentreErrors errors;
  for (int s = 0; s < segments.count; ++s) {
    const cv::Point2f c = segments.centroids[s];
    const double error = std::abs(planes[s].plane.At(c.x, c.y) - truth(c.x, c.y));
    errors.worst = std::max(errors.worst, error);
    errors.mean += error / segments.count;
  }
  return errors;
}

TEST(CoplanarGroupsTest, SegmentsOnOnePlaneShareABetterPlaneAndADepthStepSplitsThem) {
  const InversePlane left{0.0005, 0.001, 0.3};
  const auto truth = [&](double x, double y) { return left.At(x, y) + (x >= kCols / 2 ? 0.05 : 0.0); };
  const Superpixels segments = testing::BlockSegments(kCols, kRows, kBlockPx);
  const cv::Mat u = NoisyInverseDepth(truth, 7);
  const cv::Mat weight(kRows, kCols, CV_32F, cv::Scalar(1.0f));
  std::vector<SegmentPlane> planes = FitSegmentPlanes(segments, u, weight, FitOptions());
  const CentreErrors own = CentreError(planes, segments, truth);

  const CoplanarGroups groups =
      MergeCoplanarSegments(segments, SegmentPixels(segments), u, weight, GroupOptions(), &planes);
  EXPECT_EQ(groups.groups, 2);
  EXPECT_EQ(groups.grouped_segments, segments.count);
  std::set<int> left_groups, right_groups;
  for (int s = 0; s < segments.count; ++s) {
    (segments.centroids[s].x < kCols / 2 ? left_groups : right_groups).insert(groups.group_of[s]);
  }
  EXPECT_EQ(left_groups.size(), 1u);
  EXPECT_EQ(right_groups.size(), 1u);
  EXPECT_NE(*left_groups.begin(), *right_groups.begin());
  const CentreErrors grouped = CentreError(planes, segments, truth);
  std::printf("centre error, mean / worst: own planes %.5f / %.5f, group planes %.5f / %.5f\n",
              own.mean,
              own.worst,
              grouped.mean,
              grouped.worst);
  EXPECT_LT(grouped.mean, 0.25 * own.mean);
  EXPECT_LT(grouped.worst, 0.5 * own.worst);
}

TEST(CoplanarGroupsTest, ACurvedSurfaceIsCutIntoFacetsThatFitIt) {
  // A bowl: 0.09 from plane to rim, about 0.002 across one segment.
  const auto truth = [](double x, double y) {
    const double dx = x - kCols / 2.0, dy = y - kRows / 2.0;
    return 0.3 + 0.09 * (dx * dx + dy * dy) / (48.0 * 48.0 + 32.0 * 32.0);
  };
  const Superpixels segments = testing::BlockSegments(kCols, kRows, kBlockPx);
  const cv::Mat u = NoisyInverseDepth(truth, 11);
  const cv::Mat weight(kRows, kCols, CV_32F, cv::Scalar(1.0f));
  std::vector<SegmentPlane> planes = FitSegmentPlanes(segments, u, weight, FitOptions());

  const CoplanarGroups groups =
      MergeCoplanarSegments(segments, SegmentPixels(segments), u, weight, GroupOptions(), &planes);
  EXPECT_GT(groups.groups, 4) << "one plane cannot follow the bowl";
  EXPECT_LT(CentreError(planes, segments, truth).worst, kTolerance);
}

TEST(CoplanarGroupsTest, SegmentsWithoutAFittedPlaneStayOut) {
  const InversePlane truth_plane{0.0, 0.0, 0.4};
  const auto truth = [&](double x, double y) { return truth_plane.At(x, y); };
  const Superpixels segments = testing::BlockSegments(kCols, kRows, kBlockPx);
  const cv::Mat u = NoisyInverseDepth(truth, 3);
  const cv::Mat weight(kRows, kCols, CV_32F, cv::Scalar(1.0f));
  std::vector<SegmentPlane> planes = FitSegmentPlanes(segments, u, weight, FitOptions());
  planes[5].source = PlaneSource::kPropagated;
  planes[5].plane = InversePlane{0, 0, 0.9};
  planes[6].support = 0.01f;
  const InversePlane weak_plane = planes[6].plane;

  const CoplanarGroups groups =
      MergeCoplanarSegments(segments, SegmentPixels(segments), u, weight, GroupOptions(), &planes);
  EXPECT_EQ(groups.groups, 1);
  EXPECT_EQ(groups.group_of[5], -1);
  EXPECT_EQ(groups.group_of[6], -1);
  EXPECT_EQ(planes[5].plane.c, 0.9);
  EXPECT_EQ(planes[6].plane.c, weak_plane.c);
  EXPECT_EQ(groups.grouped_segments, segments.count - 2);
}

}  // namespace
}  // namespace px::depth
