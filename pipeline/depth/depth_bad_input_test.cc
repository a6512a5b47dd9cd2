// Bad input to the depth stage: a view of another scene, black and saturated views, exposure
// differences between lenses, no texture at all. No crash, low confidence where deserved, and a
// report that says which view and why; the good views keep their accuracy.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "pipeline/core/layered_depth.h"
#include "pipeline/depth/depth_stage.h"
#include "pipeline/depth/depth_stage_test_util.h"

namespace px {
namespace {

using depth::testing::BadFraction;
using depth::testing::kStageBaselineM;
using depth::testing::NearEdges;
using depth::testing::RenderGridRig;
using depth::testing::SmallCamera;
using depth::testing::SquareBeforeWall;
using depth::testing::StageTestOptions;
using depth::testing::TexturedPlane;
using depth::testing::Wall;

struct BadInputCase {
  std::vector<View> views;
  std::vector<cv::Mat> truth;
};

// The square before the wall, rendered once and shared by the cases here.
const BadInputCase& SquareBeforeWallCase() {
  static const BadInputCase* const input = [] {
    auto* rendered = new BadInputCase;
    rendered->views = SquareBeforeWall(&rendered->truth);
    return rendered;
  }();
  return *input;
}

BadInputCase WithReplacedViews(const std::vector<std::pair<int, cv::Mat>>& replacements) {
  BadInputCase input = SquareBeforeWallCase();
  for (const auto& [view, image] : replacements) input.views[view].image = image;
  return input;
}

void ExpectOthersStillGood(const DepthStageResult& result,
                           const BadInputCase& input,
                           const std::vector<int>& bad_views) {
  for (int i = 0; i < 9; ++i) {
    ASSERT_TRUE(ValidateLayeredDepthView(result.layered[i]).ok());
    if (std::find(bad_views.begin(), bad_views.end(), i) != bad_views.end()) continue;
    const cv::Mat away = NearEdges(input.truth[i], 6) == 0;
    EXPECT_LT(BadFraction(result.maps[i].depth_m, input.truth[i], away, 0.05), 0.05) << "view " << i;
  }
}

// Four neighbours per view (half the default) keep the four runs here quick.
DepthOptions BadInputOptions() {
  DepthOptions options = StageTestOptions();
  options.matching.num_neighbors = 4;
  return options;
}

// The figure the check for views of another scene reads, per view, beside its threshold.
void PrintMatchCosts(const DepthStageResult& result, const DepthOptions& options, const std::string& name) {
  std::printf("%s, filter radius %d: median best matching cost per view (threshold %.2f):",
              name.c_str(),
              options.matching.cost_filter_radius_px,
              options.max_view_match_cost);
  for (const ViewDepthReport& report : result.report.views) {
    std::printf(" %.3f (%.3f elsewhere)", report.median_match_cost, report.median_typical_cost);
  }
  std::printf("\n");
}

bool HasReason(const ViewDepthReport& report, const std::string& words) {
  for (const std::string& reason : report.reasons) {
    if (reason.find(words) != std::string::npos) return true;
  }
  return false;
}

BadInputCase WithAViewOfAnotherScene() {
  const std::vector<View> other = RenderGridRig(3, 3, kStageBaselineM, SmallCamera(), {Wall(1.5, 99)});
  return WithReplacedViews({{8, other[8].image}});
}

TEST(DepthBadInputTest, AViewOfAnotherSceneIsReportedAndLeftOut) {
  const BadInputCase input = WithAViewOfAnotherScene();
  StatusOr<DepthStageResult> result = ComputeLayeredDepth(input.views, BadInputOptions());
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  PrintMatchCosts(*result, BadInputOptions(), "another scene in view 8");
  ASSERT_EQ(result->report.disagreeing_views.size(), 1u);
  EXPECT_EQ(result->report.disagreeing_views[0].value, 8);
  const ViewDepthReport& report = result->report.views[8];
  EXPECT_TRUE(report.disagrees);
  EXPECT_EQ(report.confident_fraction, 0.0);
  EXPECT_EQ(cv::countNonZero(report.low_confidence), static_cast<int>(report.low_confidence.total()));
  EXPECT_TRUE(HasReason(report, "matches none of its neighbours"));
  EXPECT_FALSE(result->report.warnings.empty());
  ExpectOthersStillGood(*result, input, {8});
}

// The check reads the matching cost before aggregation: the same figures, and the same view told
// apart, whatever the guided filter's radius (the threshold was once set for one radius).
TEST(DepthBadInputTest, AViewOfAnotherSceneIsToldApartWhateverTheFilterRadius) {
  const BadInputCase input = WithAViewOfAnotherScene();
  std::vector<double> first_costs;
  for (const int radius : {4, 8}) {
    DepthOptions options = BadInputOptions();
    options.matching.cost_filter_radius_px = radius;
    StatusOr<DepthStageResult> result = ComputeLayeredDepth(input.views, options);
    ASSERT_TRUE(result.ok()) << result.status().ToString();
    PrintMatchCosts(*result, options, "another scene in view 8");
    ASSERT_EQ(result->report.disagreeing_views.size(), 1u) << "radius " << radius;
    EXPECT_EQ(result->report.disagreeing_views[0].value, 8) << "radius " << radius;
    for (int i = 0; i < 9; ++i) {
      // View 8's cost is its first match (against good views); the others', their second
      // (without view 8) where it was a neighbour: both independent of the filter.
      const double cost = result->report.views[i].median_match_cost;
      if (first_costs.size() < 9) {
        first_costs.push_back(cost);
      } else {
        EXPECT_DOUBLE_EQ(cost, first_costs[i]) << "view " << i;
      }
    }
    ExpectOthersStillGood(*result, input, {8});
  }
}

// One run with a black view and a saturated one in opposite corners (neither is a neighbour of
// the other, so each is judged against good views only).
TEST(DepthBadInputTest, BlackAndSaturatedViewsAreReported) {
  constexpr int kBlack = 8, kSaturated = 0;
  const BadInputCase input = WithReplacedViews({{kBlack, cv::Mat(240, 320, CV_8UC3, cv::Scalar::all(0))},
                                                {kSaturated, cv::Mat(240, 320, CV_8UC3, cv::Scalar::all(255))}});
  StatusOr<DepthStageResult> result = ComputeLayeredDepth(input.views, BadInputOptions());
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  std::vector<int> disagreeing;
  for (const auto& view : result->report.disagreeing_views) disagreeing.push_back(view.value);
  std::sort(disagreeing.begin(), disagreeing.end());
  EXPECT_EQ(disagreeing, std::vector<int>({kSaturated, kBlack}));
  for (const int view : {kBlack, kSaturated}) {
    const bool black = view == kBlack;
    const ViewDepthReport& report = result->report.views[view];
    EXPECT_TRUE(report.disagrees) << view;
    EXPECT_EQ(report.confident_fraction, 0.0) << view;
    EXPECT_DOUBLE_EQ(black ? report.dark_fraction : report.saturated_fraction, 1.0) << view;
    EXPECT_TRUE(HasReason(report, black ? "nearly black" : "saturated")) << view;
  }
  ExpectOthersStillGood(*result, input, {kBlack, kSaturated});
}

TEST(DepthBadInputTest, ExposureDifferencesBetweenLensesDoNotMatter) {
  BadInputCase input = SquareBeforeWallCase();
  // New images (the shared case's pixels must stay as rendered): darker lenses and a brighter one.
  const auto exposed = [&](int i, double gain, double offset) {
    cv::Mat image;
    input.views[i].image.convertTo(image, -1, gain, offset);
    input.views[i].image = image;
  };
  for (int i : {1, 5, 6}) exposed(i, 0.55, 10);
  exposed(3, 1.3, -5);
  StatusOr<DepthStageResult> result = ComputeLayeredDepth(input.views, BadInputOptions());
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  PrintMatchCosts(*result, BadInputOptions(), "exposure differences");
  EXPECT_TRUE(result->report.disagreeing_views.empty());
  ExpectOthersStillGood(*result, input, {});
}

// Every view matching poorly (here sensor noise in all of them, as film grain or a subject
// moving between sequential exposures would) is not a view of another scene: none is thrown
// away, the shot is warned about, and the consistency checks judge the depth.
TEST(DepthBadInputTest, AShotWhoseViewsAllMatchPoorlyIsWarnedAboutNotThrownAway) {
  BadInputCase input = SquareBeforeWallCase();
  cv::RNG rng(7);
  for (View& view : input.views) {
    cv::Mat noise(view.image.size(), CV_16SC3), noisy;
    rng.fill(noise, cv::RNG::NORMAL, 0, 10);
    cv::add(view.image, noise, noisy, cv::noArray(), CV_8UC3);
    view.image = noisy;
  }
  StatusOr<DepthStageResult> result = ComputeLayeredDepth(input.views, BadInputOptions());
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  PrintMatchCosts(*result, BadInputOptions(), "noise in every view");
  EXPECT_TRUE(result->report.disagreeing_views.empty());
  bool warned = false;
  for (const std::string& warning : result->report.warnings)
    warned = warned || warning.find("matches its neighbours poorly") != std::string::npos;
  EXPECT_TRUE(warned);
  double confident = 0;
  for (const ViewDepthReport& report : result->report.views) confident += report.confident_fraction;
  EXPECT_GT(confident / 9, 0.05) << "the depth the views agree on is kept";
}

TEST(DepthBadInputTest, TexturelessSceneGetsLowConfidenceAndSaysWhy) {
  TexturedPlane grey = Wall(2.0, 1);
  grey.texture.setTo(cv::Scalar::all(128));
  const std::vector<View> views = RenderGridRig(3, 3, kStageBaselineM, SmallCamera(), {grey});
  StatusOr<DepthStageResult> result = ComputeLayeredDepth(views, BadInputOptions());
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  // Nothing to match is not disagreement: the views are merely unconfident.
  EXPECT_TRUE(result->report.disagreeing_views.empty());
  for (int i = 0; i < 9; ++i) {
    const ViewDepthReport& report = result->report.views[i];
    ASSERT_TRUE(ValidateLayeredDepthView(result->layered[i]).ok());
    EXPECT_LT(report.confident_fraction, 0.05);
    EXPECT_GT(report.textureless_fraction, 0.95);
    EXPECT_GT(cv::countNonZero(report.low_confidence), 0.95 * report.low_confidence.total());
    EXPECT_TRUE(HasReason(report, "no texture")) << i;
  }
}

}  // namespace
}  // namespace px
