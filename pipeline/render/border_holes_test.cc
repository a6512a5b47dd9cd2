#include "pipeline/render/border_holes.h"

#include <gtest/gtest.h>

#include <cmath>

namespace px::render {
namespace {

// An image, its depth and what is known, with the unknown pixels zeroed.
struct Frame {
  Frame(int width, int height)
      : colour(height, width, CV_32FC3, cv::Scalar(0, 0, 0)),
        depth(height, width, CV_32F, cv::Scalar(2.0f)),
        known(height, width, CV_8U, cv::Scalar(255)) {}
  void Unknown(const cv::Rect& box) {
    known(box).setTo(0);
    colour(box).setTo(cv::Scalar(0, 0, 0));
    depth(box).setTo(0.0f);
  }
  cv::Mat colour, depth, known;
};

BorderHoleFillOptions Spread(float spread) {
  BorderHoleFillOptions options;
  options.spread = spread;
  return options;
}

TEST(BorderHolesTest, AnEdgeCrossingTheBorderGoesOnIntoTheHole) {
  // A floor line: red above row 20, blue below, and the 10 px at the left border unknown (a camera
  // turned left past the rig).
  Frame frame(60, 40);
  frame.colour(cv::Rect(0, 0, 60, 20)).setTo(cv::Scalar(0, 0, 255));
  frame.colour(cv::Rect(0, 20, 60, 20)).setTo(cv::Scalar(255, 0, 0));
  frame.Unknown(cv::Rect(0, 0, 10, 40));
  EXPECT_EQ(FillBorderHoles(FrameSides{}, Spread(0.5f), &frame.known, &frame.colour, &frame.depth), 400);
  EXPECT_EQ(cv::countNonZero(frame.known), 60 * 40);
  // Rows further from the line than the fade reaches (10 px * 0.5) keep their side's colour.
  for (int y : {0, 10, 14, 25, 39}) {
    for (int x = 0; x < 10; ++x) {
      const cv::Vec3f want = y < 20 ? cv::Vec3f(0, 0, 255) : cv::Vec3f(255, 0, 0);
      EXPECT_LT(cv::norm(frame.colour.at<cv::Vec3f>(y, x) - want), 1e-3) << x << "," << y;
    }
  }
  // On the line the fill blends the two sides, the more the further out (the guess fades).
  EXPECT_EQ(frame.colour.at<cv::Vec3f>(19, 9), cv::Vec3f(0, 0, 255));  // 1 px out: the edge pixel
  const cv::Vec3f far = frame.colour.at<cv::Vec3f>(19, 0);             // 10 px out
  EXPECT_GT(far[0], 40.0f);
  EXPECT_GT(far[2], 100.0f);
  EXPECT_FLOAT_EQ(frame.depth.at<float>(19, 0), 2.0f);  // depth carried out as well
}

// One-pixel columns alternating white and black, the bottom 12 rows unknown.
Frame ColumnsWithTheBottomUnknown() {
  Frame frame(40, 30);
  for (int x = 0; x < 40; x += 2) frame.colour(cv::Rect(x, 0, 1, 30)).setTo(cv::Scalar(255, 255, 255));
  frame.Unknown(cv::Rect(0, 18, 40, 12));
  return frame;
}

TEST(BorderHolesTest, FadesToTheLocalMeanWithDistance) {
  Frame frame = ColumnsWithTheBottomUnknown();
  FillBorderHoles(FrameSides{}, Spread(0.5f), &frame.known, &frame.colour, &frame.depth);
  // Next to the edge (reach 0) each column is copied; 12 px out it is near the mean grey.
  EXPECT_FLOAT_EQ(frame.colour.at<cv::Vec3f>(18, 20)[0], 255.0f);
  EXPECT_FLOAT_EQ(frame.colour.at<cv::Vec3f>(18, 21)[0], 0.0f);
  EXPECT_NEAR(frame.colour.at<cv::Vec3f>(29, 20)[0], 127.5f, 15.0f);
  EXPECT_NEAR(frame.colour.at<cv::Vec3f>(29, 21)[0], 127.5f, 15.0f);
  // Spread 0 copies straight out all the way.
  Frame copy = ColumnsWithTheBottomUnknown();
  FillBorderHoles(FrameSides{}, Spread(0.0f), &copy.known, &copy.colour, &copy.depth);
  EXPECT_FLOAT_EQ(copy.colour.at<cv::Vec3f>(29, 20)[0], 255.0f);
  EXPECT_FLOAT_EQ(copy.colour.at<cv::Vec3f>(29, 21)[0], 0.0f);
}

TEST(BorderHolesTest, EachPixelComesFromTheNearestSideItsHoleTouches) {
  // An L of unknown pixels along the left and top borders: red inside left of x = 30, blue right
  // of it, and green below row 25 on the left.
  Frame frame(60, 50);
  frame.colour.setTo(cv::Scalar(0, 0, 255));
  frame.colour(cv::Rect(30, 0, 30, 50)).setTo(cv::Scalar(255, 0, 0));
  frame.colour(cv::Rect(0, 25, 30, 25)).setTo(cv::Scalar(0, 255, 0));
  frame.Unknown(cv::Rect(0, 0, 6, 50));
  frame.Unknown(cv::Rect(0, 0, 60, 6));
  FillBorderHoles(FrameSides{}, Spread(0.0f), &frame.known, &frame.colour, &frame.depth);
  EXPECT_EQ(frame.colour.at<cv::Vec3f>(2, 45), cv::Vec3f(255, 0, 0));  // top strip: from below
  EXPECT_EQ(frame.colour.at<cv::Vec3f>(40, 2), cv::Vec3f(0, 255, 0));  // left strip: from the right
  // Where the strips cross, neither line in meets a known pixel: left to the reverse soft z.
  EXPECT_EQ(frame.known.at<uint8_t>(2, 4), 0);
  EXPECT_EQ(cv::countNonZero(frame.known == 0), 6 * 6);
}

TEST(BorderHolesTest, LeavesHolesAwayFromTheFrameBorder) {
  Frame frame(40, 30);
  frame.colour.setTo(cv::Scalar(10, 20, 30));
  frame.Unknown(cv::Rect(15, 10, 8, 8));  // a disocclusion inside the frame
  frame.Unknown(cv::Rect(0, 0, 4, 30));   // a strip on the box's left side
  FrameSides inside_the_frame;            // the box's left side is not the frame's border
  inside_the_frame.left = false;
  EXPECT_EQ(FillBorderHoles(inside_the_frame, Spread(0.5f), &frame.known, &frame.colour, &frame.depth), 0);
  EXPECT_EQ(cv::countNonZero(frame.known == 0), 8 * 8 + 4 * 30);
  // On the frame's border the strip is filled, the inner hole still left to the reverse soft z.
  EXPECT_EQ(FillBorderHoles(FrameSides{}, Spread(0.5f), &frame.known, &frame.colour, &frame.depth), 4 * 30);
  EXPECT_EQ(cv::countNonZero(frame.known == 0), 8 * 8);
  EXPECT_EQ(frame.colour.at<cv::Vec3f>(5, 0), cv::Vec3f(10, 20, 30));
}

TEST(BorderHolesTest, NothingKnownLeavesEverything) {
  Frame frame(20, 10);
  frame.Unknown(cv::Rect(0, 0, 20, 10));
  EXPECT_EQ(FillBorderHoles(FrameSides{}, Spread(0.5f), &frame.known, &frame.colour, &frame.depth), 0);
  EXPECT_EQ(cv::countNonZero(frame.known), 0);
}

TEST(BorderHolesTest, SidesOnTheFrameBorder) {
  const FrameSides all = SidesOnFrameBorder(cv::Rect(0, 0, 64, 48), cv::Size(64, 48));
  EXPECT_TRUE(all.left && all.top && all.right && all.bottom);
  const FrameSides corner = SidesOnFrameBorder(cv::Rect(40, 0, 24, 10), cv::Size(64, 48));
  EXPECT_FALSE(corner.left);
  EXPECT_TRUE(corner.top);
  EXPECT_TRUE(corner.right);
  EXPECT_FALSE(corner.bottom);
}

}  // namespace
}  // namespace px::render
