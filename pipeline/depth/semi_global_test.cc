// Semi-global aggregation and the sub-plane refinement against the raw costs.
#include "pipeline/depth/semi_global.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "pipeline/depth/select_planes.h"
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

int CountAtTrue(const PlaneSelection& selection) { return cv::countNonZero(cv::abs(selection.plane - kTrue) < 0.5); }

TEST(SemiGlobalTest, CarriesTexturedEvidenceAcrossAmbiguousPixels) {
  const cv::Mat gray(24, 24, CV_32F, cv::Scalar(0.5));  // no grey edges
  std::vector<cv::Mat> slices = AmbiguousVolume();
  const int before = CountAtTrue(SelectPlanes(slices, 1));
  EXPECT_LT(before, 24 * 24 / 2) << "the decoys must win without aggregation for the test to mean anything";
  for (int paths : {4, 8}) {
    SemiGlobalOptions options;
    options.num_paths = paths;
    const std::vector<cv::Mat> aggregated = AggregateSemiGlobal(gray, options, slices);
    EXPECT_EQ(CountAtTrue(SelectPlanes(aggregated, 1)), 24 * 24) << paths << " paths";
  }
}

TEST(SemiGlobalTest, ZeroPenaltiesLeaveCostsUnchanged) {
  const cv::Mat gray(24, 24, CV_32F, cv::Scalar(0.5));
  std::vector<cv::Mat> slices = AmbiguousVolume();
  SemiGlobalOptions options;
  options.step_penalty = 0;
  options.jump_penalty = 0;
  const std::vector<cv::Mat> aggregated = AggregateSemiGlobal(gray, options, slices);
  const std::vector<cv::Mat> raw = AmbiguousVolume();
  ASSERT_EQ(aggregated.size(), raw.size());
  for (int p = 0; p < kPlanes; ++p) {
    EXPECT_LT(cv::norm(aggregated[p], raw[p], cv::NORM_INF), 1e-5) << p;
    EXPECT_EQ(cv::norm(slices[p], raw[p], cv::NORM_INF), 0) << "the input is left as it is, plane " << p;
  }
}

// Hirschmueller's recursion written plainly, one path direction (dx, dy) at a time, in double:
// L(p, d) = C(p, d) + min(L(q, d), L(q, d -+ 1) + P1, min L(q) + P2) - min L(q), q = p - (dx, dy).
std::vector<cv::Mat> ReferenceAggregate(const cv::Mat& gray,
                                        const SemiGlobalOptions& options,
                                        const std::vector<cv::Mat>& slices) {
  const int rows = gray.rows, cols = gray.cols, planes = static_cast<int>(slices.size());
  std::vector<cv::Mat> sum(planes);
  for (cv::Mat& slice : sum) slice = cv::Mat::zeros(gray.size(), CV_64F);
  const int directions[8][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}, {1, 1}, {-1, 1}, {1, -1}, {-1, -1}};
  for (int r = 0; r < options.num_paths; ++r) {
    const int dx = directions[r][0], dy = directions[r][1];
    std::vector<cv::Mat> path(planes);
    for (cv::Mat& slice : path) slice = cv::Mat::zeros(gray.size(), CV_64F);
    for (int iy = 0; iy < rows; ++iy) {
      const int y = dy >= 0 ? iy : rows - 1 - iy;
      for (int ix = 0; ix < cols; ++ix) {
        const int x = dx >= 0 ? ix : cols - 1 - ix;
        const int qx = x - dx, qy = y - dy;
        const bool first = qx < 0 || qx >= cols || qy < 0 || qy >= rows;
        double prev_min = 0;
        double p2 = options.jump_penalty;
        if (!first) {
          prev_min = path[0].at<double>(qy, qx);
          for (int d = 1; d < planes; ++d) prev_min = std::min(prev_min, path[d].at<double>(qy, qx));
          if (std::abs(gray.at<float>(y, x) - gray.at<float>(qy, qx)) >= options.edge_gray) {
            p2 = std::max(options.step_penalty, options.jump_penalty / 3);
          }
        }
        for (int d = 0; d < planes; ++d) {
          double value = slices[d].at<float>(y, x);
          if (!first) {
            double best = std::min(path[d].at<double>(qy, qx), prev_min + p2);
            if (d > 0) best = std::min(best, path[d - 1].at<double>(qy, qx) + options.step_penalty);
            if (d + 1 < planes) best = std::min(best, path[d + 1].at<double>(qy, qx) + options.step_penalty);
            value += best - prev_min;
          }
          path[d].at<double>(y, x) = value;
        }
      }
    }
    for (int d = 0; d < planes; ++d) sum[d] += path[d] / options.num_paths;
  }
  return sum;
}

TEST(SemiGlobalTest, MatchesThePlainRecursionOnRandomCostsAndEdges) {
  cv::RNG rng(7);
  cv::Mat gray(17, 23, CV_32F);
  rng.fill(gray, cv::RNG::UNIFORM, 0.0, 1.0);  // grey steps above and below edge_gray
  std::vector<cv::Mat> slices(kPlanes);
  for (cv::Mat& slice : slices) {
    slice.create(gray.size(), CV_32F);
    rng.fill(slice, cv::RNG::UNIFORM, 0.0, 1.0);
  }
  for (int paths : {4, 8}) {
    SemiGlobalOptions options;
    options.num_paths = paths;
    options.step_penalty = 0.05f;
    options.jump_penalty = 0.3f;
    const std::vector<cv::Mat> aggregated = AggregateSemiGlobal(gray, options, slices);
    const std::vector<cv::Mat> expected = ReferenceAggregate(gray, options, slices);
    ASSERT_EQ(aggregated.size(), expected.size());
    for (int p = 0; p < kPlanes; ++p) {
      cv::Mat as_double;
      aggregated[p].convertTo(as_double, CV_64F);
      EXPECT_LT(cv::norm(as_double, expected[p], cv::NORM_INF), 1e-4) << paths << " paths, plane " << p;
    }
  }
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
