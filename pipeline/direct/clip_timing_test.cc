#include "pipeline/direct/clip_timing.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace px {
namespace {

std::vector<double> Times(const ClipTiming& timing, double fps, double duration_s) {
  std::vector<double> times;
  for (int i = 0; i < timing.NumFrames(fps, duration_s); ++i) times.push_back(timing.FrameTime(i, fps, duration_s));
  return times;
}

TEST(ClipTimingTest, OnceLinearIsThePapersEvenMove) {
  const std::vector<double> t = Times({ClipStyle::kOnce, ClipEase::kLinear, 0}, 10, 1);
  ASSERT_EQ(t.size(), 10u);
  for (size_t i = 0; i < t.size(); ++i) EXPECT_NEAR(t[i], i / 9.0, 1e-15);
}

TEST(ClipTimingTest, SmoothEaseStartsAndStopsGentlyAndIsFastestInTheMiddle) {
  const std::vector<double> t = Times({ClipStyle::kOnce, ClipEase::kSmooth, 0}, 30, 2);
  ASSERT_EQ(t.size(), 60u);
  EXPECT_EQ(t.front(), 0.0);
  EXPECT_EQ(t.back(), 1.0);
  const double first_step = t[1] - t[0];
  const double middle_step = t[30] - t[29];
  const double last_step = t[59] - t[58];
  EXPECT_LT(first_step, 0.1 * middle_step);
  EXPECT_LT(last_step, 0.1 * middle_step);
  EXPECT_NEAR(middle_step, 1.5 / 59, 0.01 / 59);  // smoothstep's top speed
  for (size_t i = 1; i < t.size(); ++i) EXPECT_GT(t[i], t[i - 1]);
}

TEST(ClipTimingTest, OnceHoldsItsLastFrame) {
  const ClipTiming timing{ClipStyle::kOnce, ClipEase::kSmooth, 0.5};
  const std::vector<double> t = Times(timing, 10, 1);
  ASSERT_EQ(t.size(), 15u);
  for (size_t i = 9; i < 15; ++i) EXPECT_EQ(t[i], 1.0);
}

TEST(ClipTimingTest, ALoopGoesOutAndBackAndRepeatsWithoutAJump) {
  const ClipTiming timing{ClipStyle::kLoop, ClipEase::kSmooth, 0};
  const std::vector<double> t = Times(timing, 30, 2);
  ASSERT_EQ(t.size(), 60u);
  EXPECT_EQ(t[0], 0.0);
  EXPECT_EQ(t[30], 1.0);
  // Frame 60 would be frame 0: the last step back is as small as the first step out.
  EXPECT_NEAR(t[59] - 0.0, t[1] - t[0], 1e-15);
  for (int i = 1; i < 30; ++i) EXPECT_EQ(t[i], t[60 - i]) << "frame " << i << " and its way back";
}

TEST(ClipTimingTest, ABoomerangPlaysTheMoveThenTheSameFramesBackwards) {
  const ClipTiming timing{ClipStyle::kBoomerang, ClipEase::kLinear, 0};
  const std::vector<double> t = Times(timing, 10, 1);
  ASSERT_EQ(t.size(), 19u);
  EXPECT_EQ(t[9], 1.0);
  EXPECT_EQ(t[18], 0.0);
  for (int i = 0; i < 9; ++i) EXPECT_EQ(t[i], t[18 - i]);
}

TEST(ClipTimingTest, NamesParseAndBadOnesAreErrors) {
  EXPECT_EQ(ParseClipStyle("boomerang").value(), ClipStyle::kBoomerang);
  EXPECT_EQ(ParseClipEase("linear").value(), ClipEase::kLinear);
  EXPECT_EQ(ParseClipStyle("spin").status().message(), "'spin' is not one of once, loop, boomerang");
  EXPECT_FALSE((ClipTiming{ClipStyle::kLoop, ClipEase::kSmooth, 1}).Validate().ok());
  EXPECT_FALSE((ClipTiming{ClipStyle::kOnce, ClipEase::kSmooth, -1}).Validate().ok());
}

}  // namespace
}  // namespace px
