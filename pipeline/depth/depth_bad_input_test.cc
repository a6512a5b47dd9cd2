// Bad input to the depth stage: a view of another scene, black and saturated views, exposure
// differences between lenses, no texture at all. No crash, low confidence where deserved, and a
// report that says which view and why; the good views keep their accuracy.
#include <string>
#include <vector>

#include <gtest/gtest.h>

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

BadInputCase WithReplacedView(const cv::Mat& image) {
  BadInputCase input;
  input.views = SquareBeforeWall(&input.truth);
  input.views[8].image = image;
  return input;
}

void ExpectOthersStillGood(const DepthStageResult& result, const BadInputCase& input, int bad_view) {
  for (int i = 0; i < 9; ++i) {
    ASSERT_TRUE(ValidateLayeredDepthView(result.layered[i]).ok());
    if (i == bad_view) continue;
    const cv::Mat away = NearEdges(input.truth[i], 6) == 0;
    EXPECT_LT(BadFraction(result.maps[i].depth_m, input.truth[i], away, 0.05), 0.05) << "view " << i;
  }
}

// Four neighbours per view (half the default) keep the five runs here quick.
DepthOptions BadInputOptions() {
  DepthOptions options = StageTestOptions();
  options.matching.num_neighbors = 4;
  return options;
}

bool HasReason(const ViewDepthReport& report, const std::string& words) {
  for (const std::string& reason : report.reasons) {
    if (reason.find(words) != std::string::npos) return true;
  }
  return false;
}

TEST(DepthBadInputTest, AViewOfAnotherSceneIsReportedAndLeftOut) {
  const std::vector<View> other = RenderGridRig(3, 3, kStageBaselineM, SmallCamera(), {Wall(1.5, 99)});
  const BadInputCase input = WithReplacedView(other[8].image);
  StatusOr<DepthStageResult> result = ComputeLayeredDepth(input.views, BadInputOptions());
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  ASSERT_EQ(result->report.disagreeing_views.size(), 1u);
  EXPECT_EQ(result->report.disagreeing_views[0].value, 8);
  const ViewDepthReport& report = result->report.views[8];
  EXPECT_TRUE(report.disagrees);
  EXPECT_EQ(report.confident_fraction, 0.0);
  EXPECT_EQ(cv::countNonZero(report.low_confidence), static_cast<int>(report.low_confidence.total()));
  EXPECT_TRUE(HasReason(report, "matches none of its neighbours"));
  EXPECT_FALSE(result->report.warnings.empty());
  ExpectOthersStillGood(*result, input, 8);
}

TEST(DepthBadInputTest, BlackAndSaturatedViewsAreReported) {
  for (const int level : {0, 255}) {
    const BadInputCase input = WithReplacedView(cv::Mat(240, 320, CV_8UC3, cv::Scalar::all(level)));
    StatusOr<DepthStageResult> result = ComputeLayeredDepth(input.views, BadInputOptions());
    ASSERT_TRUE(result.ok()) << result.status().ToString();
    const ViewDepthReport& report = result->report.views[8];
    EXPECT_TRUE(report.disagrees) << level;
    EXPECT_EQ(report.confident_fraction, 0.0) << level;
    EXPECT_DOUBLE_EQ(level == 0 ? report.dark_fraction : report.saturated_fraction, 1.0);
    EXPECT_TRUE(HasReason(report, level == 0 ? "nearly black" : "saturated")) << level;
    ExpectOthersStillGood(*result, input, 8);
  }
}

TEST(DepthBadInputTest, ExposureDifferencesBetweenLensesDoNotMatter) {
  BadInputCase input;
  input.views = SquareBeforeWall(&input.truth);
  for (int i : {1, 5, 6}) input.views[i].image.convertTo(input.views[i].image, -1, 0.55, 10);
  input.views[3].image.convertTo(input.views[3].image, -1, 1.3, -5);
  StatusOr<DepthStageResult> result = ComputeLayeredDepth(input.views, BadInputOptions());
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  EXPECT_TRUE(result->report.disagreeing_views.empty());
  ExpectOthersStillGood(*result, input, -1);
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
