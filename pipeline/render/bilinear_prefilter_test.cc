// The bilinear prefilter sharpens colour edges within a surface (one segment, or touching segments
// whose planes agree) and never across a depth edge.
#include "pipeline/render/bilinear_prefilter.h"

#include <gtest/gtest.h>

namespace px::render {
namespace {

// One layer, 12x6: segment 0 on columns 0..5 with a grey step (100 | 160) between columns 2 and 3;
// segment 1 on columns 6..11, flat 40.
LayeredDepthView StepView() {
  LayeredDepthView view;
  view.camera = CameraModel::Pinhole(12, 6, 10.0);
  view.segments.resize(2);
  for (SegmentLayer& layer : view.layers) {
    layer.colour = cv::Mat(6, 12, CV_8UC3, cv::Scalar(0, 0, 0));
    layer.weight = cv::Mat(6, 12, CV_32F, cv::Scalar(0));
    layer.segment = cv::Mat(6, 12, CV_32S, cv::Scalar(SegmentLayer::kNoSegment));
  }
  SegmentLayer& front = view.layers[0];
  front.weight.setTo(1.0f);
  front.segment.colRange(6, 12).setTo(1);
  front.segment.colRange(0, 6).setTo(0);
  front.colour.colRange(0, 3).setTo(cv::Scalar(100, 100, 100));
  front.colour.colRange(3, 6).setTo(cv::Scalar(160, 160, 160));
  front.colour.colRange(6, 12).setTo(cv::Scalar(40, 40, 40));
  return view;
}

TEST(BilinearPrefilterTest, SharpensEdgesWithinASegmentOnly) {
  const LayeredDepthView view = StepView();
  const std::array<cv::Mat, 2> colours = PrefilterForBilinear(view);
  const int y = 3;
  // Either side of the step moves away from the other by 60 / 12 = 5 levels.
  EXPECT_EQ(colours[0].at<cv::Vec3b>(y, 2), cv::Vec3b(95, 95, 95));
  EXPECT_EQ(colours[0].at<cv::Vec3b>(y, 3), cv::Vec3b(165, 165, 165));
  // Flat parts, and the border between segments 0 (160) and 1 (40): unchanged.
  EXPECT_EQ(colours[0].at<cv::Vec3b>(y, 0), cv::Vec3b(100, 100, 100));
  EXPECT_EQ(colours[0].at<cv::Vec3b>(y, 5), cv::Vec3b(160, 160, 160));
  EXPECT_EQ(colours[0].at<cv::Vec3b>(y, 6), cv::Vec3b(40, 40, 40));
  // An empty layer stays as it was; sharpen 0 changes nothing.
  EXPECT_EQ(cv::countNonZero(colours[1].reshape(1)), 0);
  const std::array<cv::Mat, 2> unchanged = PrefilterForBilinear(view, 0);
  EXPECT_EQ(cv::norm(unchanged[0], view.layers[0].colour, cv::NORM_INF), 0);
}

TEST(BilinearPrefilterTest, ANeighbourInTheOtherLayerCounts) {
  // Column 4 moves segment 0 to layer 1 (a boundary texel behind segment 1): still a neighbour.
  LayeredDepthView view = StepView();
  view.layers[0].segment.col(4).setTo(1);
  view.layers[0].colour.col(4).setTo(cv::Scalar(40, 40, 40));
  view.layers[0].weight.col(4).setTo(0.5f);
  view.layers[1].segment.col(4).setTo(0);
  view.layers[1].colour.col(4).setTo(cv::Scalar(220, 220, 220));
  view.layers[1].weight.col(4).setTo(0.5f);
  const std::array<cv::Mat, 2> colours = PrefilterForBilinear(view);
  // Column 3 (160) between 100 and layer 1's 220: the Laplacian cancels, unchanged.
  EXPECT_EQ(colours[0].at<cv::Vec3b>(2, 3), cv::Vec3b(160, 160, 160));
  // Layer 1 at column 4: 220 next to 160 (left) and 160 (right, column 5): 220 + 120 / 12 = 230.
  EXPECT_EQ(colours[1].at<cv::Vec3b>(2, 4), cv::Vec3b(230, 230, 230));
}

// StepView with segment 0's step (columns 0..2 | 3..5) split into two segments: 0 on columns 0..2
// and 2 on columns 3..5, on planes of inverse depth u0 and u2; segment 1 far behind (0.1).
LayeredDepthView SplitStepView(double u0, double u2) {
  LayeredDepthView view = StepView();
  view.segments.resize(3);
  view.segments[0].inv_depth_c = u0;
  view.segments[1].inv_depth_c = 0.1;
  view.segments[2].inv_depth_c = u2;
  view.layers[0].segment.colRange(3, 6).setTo(2);
  return view;
}

TEST(BilinearPrefilterTest, SharpensAcrossSegmentsOfOneSurface) {
  // One plane cut in two by the segmentation: the step is sharpened as within one segment.
  const std::array<cv::Mat, 2> colours = PrefilterForBilinear(SplitStepView(0.5, 0.5));
  const int y = 3;
  EXPECT_EQ(colours[0].at<cv::Vec3b>(y, 2), cv::Vec3b(95, 95, 95));
  EXPECT_EQ(colours[0].at<cv::Vec3b>(y, 3), cv::Vec3b(165, 165, 165));
  // Segment 2 (160, inverse depth 0.5) against segment 1 (40, 0.1): a depth edge, unchanged.
  EXPECT_EQ(colours[0].at<cv::Vec3b>(y, 5), cv::Vec3b(160, 160, 160));
  EXPECT_EQ(colours[0].at<cv::Vec3b>(y, 6), cv::Vec3b(40, 40, 40));
  // Within the tolerance (0.4 % apart) still one surface.
  const std::array<cv::Mat, 2> near = PrefilterForBilinear(SplitStepView(0.5, 0.502));
  EXPECT_EQ(near[0].at<cv::Vec3b>(y, 2), cv::Vec3b(95, 95, 95));
}

TEST(BilinearPrefilterTest, StopsAtADepthEdgeBetweenSegments) {
  // 2 % apart in inverse depth: two surfaces, so the step between them stays as it is.
  const std::array<cv::Mat, 2> colours = PrefilterForBilinear(SplitStepView(0.5, 0.51));
  const int y = 3;
  EXPECT_EQ(colours[0].at<cv::Vec3b>(y, 2), cv::Vec3b(100, 100, 100));
  EXPECT_EQ(colours[0].at<cv::Vec3b>(y, 3), cv::Vec3b(160, 160, 160));
  // A plane at or behind infinity continues no surface; a bad segment index is skipped.
  LayeredDepthView bad = SplitStepView(0, 0);
  bad.layers[0].segment.at<int32_t>(y, 4) = 99;
  const std::array<cv::Mat, 2> unchanged = PrefilterForBilinear(bad);
  EXPECT_EQ(unchanged[0].at<cv::Vec3b>(y, 2), cv::Vec3b(100, 100, 100));
  EXPECT_EQ(unchanged[0].at<cv::Vec3b>(y, 3), cv::Vec3b(160, 160, 160));
}

}  // namespace
}  // namespace px::render
