// Semi-global aggregation and the sub-plane refinement against the raw costs.
#include <vector>

#include <gtest/gtest.h>

#include "pipeline/depth/select_planes.h"
#include "pipeline/depth/semi_global.h"
#include "pipeline/depth/sub_plane.h"

namespace px::depth {
namespace {

constexpr int kPlanes = 12;
constexpr int kTrue = 4;

// A 24x24 cost volume: the left third has a clear minimum at kTrue; the rest is textureless
// (the same cost at every plane), where a winner-take-all choice is arbitrary.
std::vector<cv::Mat> AmbiguousVolume() {
  std::vector<cv::Mat> slices(kPlanes);
  for (int p = 0; p < kPlanes; ++p) {
    slices[p] = cv::Mat(24, 24, CV_32F, cv::Scalar(0.9));
    slices[p](cv::Rect(0, 0, 8, 24)).setTo(p == kTrue ? 0.1 : 0.8);
  }
  return slices;
}

int CountAtTrue(const PlaneSelection& selection) {
  return cv::countNonZero(cv::abs(selection.plane - kTrue) < 0.5);
}

TEST(SemiGlobalTest, CarriesTexturedEvidenceAcrossAmbiguousPixels) {
  const cv::Mat gray(24, 24, CV_32F, cv::Scalar(0.5));  // no grey edges
  std::vector<cv::Mat> slices = AmbiguousVolume();
  const int before = CountAtTrue(SelectPlanes(slices, 1));
  EXPECT_LT(before, 24 * 24 / 2) << "the decoys must win without aggregation for the test to mean anything";
  for (int paths : {4, 8}) {
    std::vector<cv::Mat> aggregated = AmbiguousVolume();
    SemiGlobalOptions options;
    options.num_paths = paths;
    AggregateSemiGlobal(gray, options, &aggregated);
    EXPECT_EQ(CountAtTrue(SelectPlanes(aggregated, 1)), 24 * 24) << paths << " paths";
  }
}

TEST(SemiGlobalTest, ZeroPenaltiesLeaveCostsUnchanged) {
  const cv::Mat gray(24, 24, CV_32F, cv::Scalar(0.5));
  std::vector<cv::Mat> slices = AmbiguousVolume();
  SemiGlobalOptions options;
  options.step_penalty = 0;
  options.jump_penalty = 0;
  AggregateSemiGlobal(gray, options, &slices);
  const std::vector<cv::Mat> raw = AmbiguousVolume();
  for (int p = 0; p < kPlanes; ++p) EXPECT_LT(cv::norm(slices[p], raw[p], cv::NORM_INF), 1e-5) << p;
}

TEST(SubPlaneTest, RefinesTowardsTheRawCostMinimum) {
  // Raw costs: a parabola with its minimum at plane 6.3.
  std::vector<cv::Mat> raw(kPlanes);
  for (int p = 0; p < kPlanes; ++p) raw[p] = cv::Mat(2, 2, CV_32F, cv::Scalar(0.1 + 0.01 * (p - 6.3) * (p - 6.3)));
  cv::Mat winner(2, 2, CV_32F, cv::Scalar(5.0f));  // the aggregate's choice, a plane off
  RefineAroundWinners(raw, 2, /*wide_fit=*/true, &winner);
  EXPECT_NEAR(winner.at<float>(0, 0), 6.3f, 1e-3);
  winner.setTo(5.0f);
  RefineAroundWinners(raw, 2, /*wide_fit=*/false, &winner);
  EXPECT_NEAR(winner.at<float>(0, 0), 6.3f, 1e-3);
  cv::Mat far(2, 2, CV_32F, cv::Scalar(1.0f));  // beyond the search: stays near the aggregate's basin
  RefineAroundWinners(raw, 2, /*wide_fit=*/true, &far);
  EXPECT_LT(far.at<float>(0, 0), 4.5f);
}

}  // namespace
}  // namespace px::depth
