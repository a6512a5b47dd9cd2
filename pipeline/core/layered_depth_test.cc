#include "pipeline/core/layered_depth.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace px {
namespace {

using ::testing::HasSubstr;

// A 40x30 view: a fronto-parallel background at 4 m, a foreground square at 1 m whose left
// edge column is split 60/40 between the two.
LayeredDepthView TwoLayerView() {
  LayeredDepthView view;
  view.id = ViewId{3};
  view.camera = CameraModel::Pinhole(40, 30, 50);
  DepthSegment background;
  background.inv_depth_c = 0.25;
  background.bbox = cv::Rect(0, 0, 40, 30);
  background.confidence = 0.9f;
  DepthSegment foreground;
  foreground.inv_depth_c = 1.0;
  foreground.bbox = cv::Rect(10, 10, 10, 10);
  foreground.confidence = 0.8f;
  view.segments = {background, foreground};
  for (SegmentLayer& layer : view.layers) {
    layer.colour = cv::Mat(30, 40, CV_8UC3, cv::Scalar(0, 0, 0));
    layer.weight = cv::Mat::zeros(30, 40, CV_32F);
    layer.segment = cv::Mat(30, 40, CV_32S, cv::Scalar(SegmentLayer::kNoSegment));
  }
  view.layers[0].weight.setTo(1);
  view.layers[0].segment.setTo(0);
  view.layers[0].segment(foreground.bbox).setTo(1);
  view.layers[0].weight(cv::Rect(10, 10, 1, 10)).setTo(0.6);
  view.layers[1].weight(cv::Rect(10, 10, 1, 10)).setTo(0.4);
  view.layers[1].segment(cv::Rect(10, 10, 1, 10)).setTo(0);
  view.depth_m = cv::Mat(30, 40, CV_32F, cv::Scalar(4.0));
  view.depth_m(foreground.bbox).setTo(1.0);
  view.confidence = cv::Mat(30, 40, CV_32F, cv::Scalar(1.0));
  for (DepthSegment& segment : view.segments) segment.num_pixels = 1;
  return view;
}

TEST(LayeredDepth, ValidViewPassesAndGivesLayerDepths) {
  const LayeredDepthView view = TwoLayerView();
  ASSERT_TRUE(ValidateLayeredDepthView(view).ok()) << ValidateLayeredDepthView(view).ToString();
  EXPECT_DOUBLE_EQ(view.LayerDepthAt(0, 10, 12), 1.0);
  EXPECT_DOUBLE_EQ(view.LayerDepthAt(1, 10, 12), 4.0);
  EXPECT_DOUBLE_EQ(view.LayerDepthAt(1, 30, 5), 0.0);  // one layer only there
  EXPECT_EQ(view.ToDepthMap().depth_m.data, view.depth_m.data);
}

TEST(LayeredDepth, SlantedPlaneDepthIsAffineInInverseDepth) {
  DepthSegment slanted;
  slanted.inv_depth_a = 0.01;
  slanted.inv_depth_c = 0.5;
  EXPECT_DOUBLE_EQ(slanted.DepthAt(0, 7), 2.0);
  EXPECT_DOUBLE_EQ(slanted.DepthAt(50, 7), 1.0);
  EXPECT_DOUBLE_EQ(slanted.DepthAt(-50, 7), 0.0);  // at infinity: no depth
}

TEST(LayeredDepth, WeightsThatDoNotSumToOneAreNamed) {
  LayeredDepthView view = TwoLayerView();
  view.layers[1].weight.at<float>(12, 10) = 0.1f;
  const Status status = ValidateLayeredDepthView(view);
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(), HasSubstr("view 3, pixel (10, 12): layer weights sum to 0.7"));
}

TEST(LayeredDepth, BadSegmentIndexSizeAndPlaneAreNamed) {
  LayeredDepthView view = TwoLayerView();
  view.layers[0].segment.at<int32_t>(2, 3) = 7;
  EXPECT_THAT(ValidateLayeredDepthView(view).message(),
              HasSubstr("layer 0, pixel (3, 2): weight 1 but segment index 7"));

  view = TwoLayerView();
  view.layers[0].segment.at<int32_t>(2, 3) = 1;  // the foreground segment, outside its bbox
  EXPECT_THAT(ValidateLayeredDepthView(view).message(), HasSubstr("segment 1 covers it outside its bbox"));

  view = TwoLayerView();
  view.layers[1].weight = cv::Mat::zeros(29, 40, CV_32F);
  EXPECT_THAT(ValidateLayeredDepthView(view).message(), HasSubstr("layer 1: weight: got 40x29"));

  view = TwoLayerView();
  view.segments[1].inv_depth_a = -1.0;  // 1/z = -x + 1: negative across the bbox
  EXPECT_THAT(ValidateLayeredDepthView(view).message(), HasSubstr("segment 1: its plane has no positive depth"));
}

}  // namespace
}  // namespace px
