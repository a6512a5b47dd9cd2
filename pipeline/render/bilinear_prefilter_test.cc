// The bilinear prefilter sharpens colour edges within a segment and never across segments.
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

}  // namespace
}  // namespace px::render
