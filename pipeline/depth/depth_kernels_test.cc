// Unit tests of the plane sweep's building blocks against straightforward reference versions.
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "pipeline/depth/best_half_aggregation.h"
#include "pipeline/depth/box_mean.h"
#include "pipeline/depth/cost_filter.h"
#include "pipeline/depth/depth_cleanup.h"
#include "pipeline/depth/fill_unconfirmed.h"
#include "pipeline/depth/plane_warp.h"
#include "pipeline/depth/select_planes.h"
#include "pipeline/depth/zncc_cost.h"

namespace px::depth {
namespace {

cv::Mat RandomImage(cv::Size size, uint64_t seed) {
  cv::Mat image(size, CV_32F);
  cv::RNG rng(seed);
  rng.fill(image, cv::RNG::UNIFORM, 0.0, 1.0);
  cv::GaussianBlur(image, image, cv::Size(0, 0), 1.0);  // some spatial correlation, like images
  return image;
}

TEST(BoxMeanTest, MatchesOpenCvBoxFilterWithReflectedBorders) {
  const cv::Mat image = RandomImage(cv::Size(37, 23), 1);
  for (int radius : {1, 3, 6, 9}) {
    cv::Mat ours, expected;
    std::vector<float> scratch;
    BoxMean(image, radius, &scratch, &ours);
    cv::boxFilter(
        image, expected, CV_32F, cv::Size(2 * radius + 1, 2 * radius + 1), cv::Point(-1, -1), true, cv::BORDER_REFLECT);
    // Float running sums over 23 rows: agreement to 1e-5 of values in [0, 1].
    EXPECT_LT(cv::norm(ours, expected, cv::NORM_INF), 1e-5) << "radius " << radius;
  }
}

TEST(ZnccCostTest, MatchesDirectComputationAndIsZeroForAnAffineCopy) {
  const cv::Mat ref = RandomImage(cv::Size(40, 30), 2);
  const cv::Mat other = RandomImage(cv::Size(40, 30), 3);
  const int radius = 3;
  const ReferenceWindows windows = PrepareReferenceWindows(ref, radius, 0.0);
  ZnccWorkspace workspace;
  cv::Mat cost;
  ComputeZnccCost(windows, other, cv::Mat(), &workspace, &cost);
  cv::Mat padded_ref, padded_other;
  cv::copyMakeBorder(ref, padded_ref, radius, radius, radius, radius, cv::BORDER_REFLECT);
  cv::copyMakeBorder(other, padded_other, radius, radius, radius, radius, cv::BORDER_REFLECT);
  for (const cv::Point p : {cv::Point(0, 0), cv::Point(20, 15), cv::Point(39, 29), cv::Point(5, 28)}) {
    const cv::Rect window(p.x, p.y, 2 * radius + 1, 2 * radius + 1);  // in padded coordinates
    cv::Scalar mean_a, std_a, mean_b, std_b;
    cv::meanStdDev(padded_ref(window), mean_a, std_a);
    cv::meanStdDev(padded_other(window), mean_b, std_b);
    const double covariance = cv::mean((padded_ref(window) - mean_a[0]).mul(padded_other(window) - mean_b[0]))[0];
    const double expected = 1.0 - covariance / (std_a[0] * std_b[0]);
    EXPECT_NEAR(cost.at<float>(p), expected, 1e-3) << p;
  }
  // Gain and offset do not matter to ZNCC.
  ComputeZnccCost(windows, 0.5 * ref + 0.2, cv::Mat(), &workspace, &cost);
  double max_cost = 0;
  cv::minMaxLoc(cost, nullptr, &max_cost);
  EXPECT_LT(max_cost, 1e-3);
}

TEST(ZnccCostTest, TexturelessReferenceIsNeutralAndInvalidSamplesAreMarked) {
  const cv::Mat flat(20, 20, CV_32F, cv::Scalar(0.5));
  const ReferenceWindows windows = PrepareReferenceWindows(flat, 2, 0.004);
  ZnccWorkspace workspace;
  cv::Mat valid(20, 20, CV_8U, cv::Scalar(255));
  valid(cv::Rect(0, 0, 5, 20)).setTo(0);
  cv::Mat cost;
  ComputeZnccCost(windows, RandomImage(cv::Size(20, 20), 4), valid, &workspace, &cost);
  EXPECT_EQ(cost.at<float>(10, 2), kInvalidCost);
  EXPECT_FLOAT_EQ(cost.at<float>(10, 10), kNeutralCost);
}

TEST(PlaneWarpTest, CubicShiftReproducesSmoothImagesAndMatchesTheGeneralWarp) {
  // A smooth image: cubic interpolation of a quadratic is exact away from the borders.
  cv::Mat quadratic(30, 40, CV_32F);
  for (int y = 0; y < 30; ++y) {
    for (int x = 0; x < 40; ++x) quadratic.at<float>(y, x) = 0.001f * (x * x + 2 * y * y) + 0.01f * x;
  }
  cv::Mat shifted;
  ShiftCubic(quadratic, 2.3, -1.6, &shifted);
  for (int y = 5; y < 25; ++y) {
    for (int x = 5; x < 30; ++x) {
      const double sx = x + 2.3, sy = y - 1.6;
      EXPECT_NEAR(shifted.at<float>(y, x), 0.001 * (sx * sx + 2 * sy * sy) + 0.01 * sx, 1e-4) << x << "," << y;
    }
  }
  // The same translation through the general path (bilinear warpPerspective) agrees to within
  // bilinear's error on this quadratic, (f_xx + f_yy) / 8 = 0.00075, plus OpenCV's 1/32 px
  // coordinate quantisation times the gradient (up to 0.08 per px): 3e-3.
  Eigen::Matrix3d h = Eigen::Matrix3d::Identity();
  h(0, 2) = 2.3;
  h(1, 2) = -1.6;
  double dx = 0, dy = 0;
  ASSERT_TRUE(IsTranslation(h, &dx, &dy));
  EXPECT_DOUBLE_EQ(dx, 2.3);
  cv::Mat fast, general;
  WarpIntoReference(quadratic, h, quadratic.size(), &fast);
  const cv::Matx33d m(1, 0, 2.3, 0, 1, -1.6, 0, 0, 1);
  cv::warpPerspective(
      quadratic, general, m, quadratic.size(), cv::INTER_LINEAR | cv::WARP_INVERSE_MAP, cv::BORDER_REPLICATE);
  EXPECT_LT(cv::norm(fast(cv::Rect(5, 5, 28, 20)), general(cv::Rect(5, 5, 28, 20)), cv::NORM_INF), 3e-3);
  h(2, 0) = 1e-4;
  EXPECT_FALSE(IsTranslation(h, &dx, &dy));
}

TEST(PlaneWarpTest, ValidMaskIsTheInsetSourceRectangleMappedBack) {
  Eigen::Matrix3d h = Eigen::Matrix3d::Identity();
  h(0, 2) = -10;  // reference x maps to source x - 10
  cv::Mat mask;
  ValidSampleMask(h, cv::Size(100, 50), 3, cv::Size(100, 50), &mask);
  // Needs 3 + 2 (window + cubic taps) <= x - 10 <= 99 - 5, and 5 <= y <= 44.
  EXPECT_EQ(mask.at<uchar>(25, 14), 0);
  EXPECT_EQ(mask.at<uchar>(25, 16), 255);
  EXPECT_EQ(mask.at<uchar>(25, 99), 255);
  EXPECT_EQ(mask.at<uchar>(3, 50), 0);
  EXPECT_EQ(mask.at<uchar>(46, 50), 0);
}

TEST(BestHalfAggregationTest, AveragesTheBestHalfOfTheValidCosts) {
  const std::vector<float> values = {0.9f, 0.1f, kInvalidCost, 0.3f, 0.5f};
  std::vector<cv::Mat> costs;
  for (float v : values) costs.emplace_back(1, 3, CV_32F, cv::Scalar(v));
  costs[0].at<float>(0, 1) = kInvalidCost;                    // pixel 1: valid 0.1, 0.3, 0.5 -> best 2: 0.2
  for (cv::Mat& c : costs) c.at<float>(0, 2) = kInvalidCost;  // pixel 2: nothing valid
  AggregationWorkspace workspace;
  cv::Mat aggregated;
  AggregateBestHalf(costs, &workspace, &aggregated);
  EXPECT_FLOAT_EQ(aggregated.at<float>(0, 0), 0.2f);  // valid 0.9, 0.1, 0.3, 0.5 -> best 2
  EXPECT_FLOAT_EQ(aggregated.at<float>(0, 1), 0.2f);
  EXPECT_FLOAT_EQ(aggregated.at<float>(0, 2), kNoDataCost);
}

// Cost curves c(p) = (p - centre)^2 / 16 + base, one per column.
std::vector<cv::Mat> ParabolicVolume(const std::vector<double>& centres, int num_planes) {
  std::vector<cv::Mat> volume;
  for (int p = 0; p < num_planes; ++p) {
    cv::Mat slice(1, static_cast<int>(centres.size()), CV_32F);
    for (size_t x = 0; x < centres.size(); ++x) {
      slice.at<float>(0, static_cast<int>(x)) = static_cast<float>(0.1 + (p - centres[x]) * (p - centres[x]) / 16.0);
    }
    volume.push_back(slice);
  }
  return volume;
}

TEST(SelectPlanesTest, RecoversTheMinimumOfAParabolaBetweenPlanes) {
  const std::vector<double> centres = {5.0, 5.3, 7.75, 2.5};
  for (int fit_half_width : {1, 2}) {
    const PlaneSelection selection = SelectPlanes(ParabolicVolume(centres, 12), fit_half_width);
    for (size_t x = 0; x < centres.size(); ++x) {
      EXPECT_NEAR(selection.plane.at<float>(0, static_cast<int>(x)), centres[x], 1e-4) << "fit " << fit_half_width;
      // Single minimum with best cost 0.1: confidence = (1 - 0.1 / max) * 0.9, well above zero.
      EXPECT_GT(selection.confidence.at<float>(0, static_cast<int>(x)), 0.5f);
    }
  }
}

TEST(SelectPlanesTest, AmbiguousAndFlatCurvesHaveLowConfidence) {
  std::vector<cv::Mat> volume;
  for (int p = 0; p < 10; ++p) {
    cv::Mat slice(1, 3, CV_32F);
    slice.at<float>(0, 0) = (p == 2 || p == 7) ? 0.1f : 0.8f;  // two equally good minima
    slice.at<float>(0, 1) = kNeutralCost;                      // textureless: flat
    slice.at<float>(0, 2) = kNoDataCost;                       // never sampled
    volume.push_back(slice);
  }
  const PlaneSelection selection = SelectPlanes(volume, 1);
  EXPECT_LT(selection.confidence.at<float>(0, 0), 0.05f);
  EXPECT_EQ(selection.confidence.at<float>(0, 1), 0.0f);
  EXPECT_EQ(selection.confidence.at<float>(0, 2), 0.0f);
}

TEST(CostFilterTest, KeepsConstantCostsAndIgnoresPixelsWithoutData) {
  const cv::Mat guide = RandomImage(cv::Size(30, 20), 6);
  const CostFilterGuide prepared = PrepareCostFilterGuide(guide, 3, 1e-4);
  CostFilterWorkspace workspace;
  cv::Mat cost(20, 30, CV_32F, cv::Scalar(0.25));
  cost(cv::Rect(0, 0, 4, 20)).setTo(kNoDataCost);  // a border strip nobody sampled
  FilterCostSlice(prepared, &workspace, &cost);
  // Costs next to the strip are not pulled towards kNoDataCost.
  EXPECT_LT(cv::norm(cost(cv::Rect(4, 0, 26, 20)) - 0.25, cv::NORM_INF), 1e-4);
}

TEST(DepthCleanupTest, SpecklesLoseConfidenceAndUpsamplingFollowsEdges) {
  cv::Mat plane(40, 40, CV_32F, cv::Scalar(10));
  plane(cv::Rect(20, 20, 3, 3)).setTo(30);  // a 9-pixel island far from its surroundings
  cv::Mat confidence(40, 40, CV_32F, cv::Scalar(0.9));
  LowerSpeckleConfidence(plane, 16, 2.0f, 0.05f, &confidence);
  EXPECT_EQ(confidence.at<float>(21, 21), 0.05f);
  EXPECT_EQ(confidence.at<float>(5, 5), 0.9f);

  // Low resolution: left half dark with value 1, right half bright with value 2. Upsampled, a
  // pixel just left of the edge takes the dark side's value, not an average.
  cv::Mat low_guide(10, 10, CV_8UC3, cv::Scalar(20, 20, 20)), low_value(10, 10, CV_32F, cv::Scalar(1));
  low_guide(cv::Rect(5, 0, 5, 10)).setTo(cv::Scalar(220, 220, 220));
  low_value(cv::Rect(5, 0, 5, 10)).setTo(2);
  cv::Mat high_guide(20, 20, CV_8UC3, cv::Scalar(20, 20, 20));
  high_guide(cv::Rect(10, 0, 10, 20)).setTo(cv::Scalar(220, 220, 220));
  const cv::Mat low_confidence(10, 10, CV_32F, cv::Scalar(1));
  cv::Mat high_value, high_confidence;
  UpsampleJointBilateral(low_value, low_confidence, low_guide, high_guide, &high_value, &high_confidence);
  ASSERT_EQ(high_value.size(), cv::Size(20, 20));
  EXPECT_NEAR(high_value.at<float>(10, 9), 1.0f, 1e-3);
  EXPECT_NEAR(high_value.at<float>(10, 10), 2.0f, 1e-3);
  EXPECT_NEAR(high_confidence.at<float>(10, 10), 1.0f, 1e-5);
}

TEST(DepthCleanupTest, FillReplacesOnlyUnreliablePixels) {
  const cv::Mat guide(30, 30, CV_8UC3, cv::Scalar(90, 90, 90));
  cv::Mat inverse_depth(30, 30, CV_32F, cv::Scalar(0.5));
  cv::Mat confidence(30, 30, CV_32F, cv::Scalar(0.8));
  inverse_depth(cv::Rect(10, 10, 5, 5)).setTo(1.5);  // unreliable patch with a wrong value
  confidence(cv::Rect(10, 10, 5, 5)).setTo(0.0);
  FillLowConfidence(guide, confidence, 0.15f, 0.1f, 2.0f, &inverse_depth);
  EXPECT_NEAR(inverse_depth.at<float>(12, 12), 0.5f, 0.01f);
  EXPECT_EQ(inverse_depth.at<float>(2, 2), 0.5f);
}

TEST(FillUnconfirmedTest, RunsTakeTheFartherConfirmedEnd) {
  // Row 0: a run between a near (2 m) and a far (5 m) confirmed pixel; row 1: a run at the left
  // border; row 2: nothing confirmed.
  cv::Mat depth = (cv::Mat_<float>(3, 6) << 2,
                   2,
                   1,
                   9,
                   5,
                   5,  //
                   7,
                   8,
                   3,
                   3,
                   3,
                   3,  //
                   4,
                   4,
                   4,
                   4,
                   4,
                   4);
  const cv::Mat confirmed = (cv::Mat_<uint8_t>(3, 6) << 255,
                             255,
                             0,
                             0,
                             255,
                             255,  //
                             0,
                             0,
                             255,
                             255,
                             255,
                             255,  //
                             0,
                             0,
                             0,
                             0,
                             0,
                             0);
  const cv::Mat before = depth.clone();
  EXPECT_EQ(FillUnconfirmedFromBackground(confirmed, &depth), 4);
  EXPECT_EQ(depth.at<float>(0, 2), 5.0f);
  EXPECT_EQ(depth.at<float>(0, 3), 5.0f);
  EXPECT_EQ(depth.at<float>(1, 0), 3.0f);
  EXPECT_EQ(depth.at<float>(1, 1), 3.0f);
  EXPECT_EQ(cv::norm(depth.row(2), before.row(2), cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(depth(cv::Rect(4, 0, 2, 1)), before(cv::Rect(4, 0, 2, 1)), cv::NORM_INF), 0.0);
}

}  // namespace
}  // namespace px::depth
