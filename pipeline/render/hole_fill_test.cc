#include "pipeline/render/hole_fill.h"

#include <gtest/gtest.h>

#include <cmath>

#include "pipeline/render/soft_z.h"

namespace px::render {
namespace {

TEST(SoftZTest, FollowsEquationOne) {
  // rho = 2 m, gamma = rho / 10 = 0.2 m: 1 up to gamma, raised cosine to 0 at rho - gamma.
  const SoftZ soft_z(2.0, 0.1);
  EXPECT_FLOAT_EQ(soft_z.gamma(), 0.2f);
  EXPECT_FLOAT_EQ(soft_z.Weight(-0.5f), 1.0f);
  EXPECT_FLOAT_EQ(soft_z.Weight(0.0f), 1.0f);
  EXPECT_FLOAT_EQ(soft_z.Weight(0.2f), 1.0f);
  EXPECT_NEAR(soft_z.Weight(1.0f), 0.5f, 1e-6);  // the middle of [gamma, rho - gamma]
  for (float dz = 0.2f; dz <= 1.8f; dz += 0.05f) {
    const double want = 0.5 * (1.0 + std::cos(M_PI * (dz - 0.2) / (2.0 - 0.4)));
    EXPECT_NEAR(soft_z.Weight(dz), want, 1e-5) << dz;
  }
  EXPECT_NEAR(soft_z.Weight(1.8f), 0.0f, 1e-6);
  EXPECT_FLOAT_EQ(soft_z.Weight(1.81f), 0.0f);
  EXPECT_FLOAT_EQ(soft_z.Weight(50.0f), 0.0f);
}

TEST(HoleScoreTest, SumsCubedDistancesOverTheArea) {
  cv::Mat coverage(40, 50, CV_8U, cv::Scalar(255));
  EXPECT_EQ(HoleScore(coverage), 0.0);
  // A one-pixel-wide line: every hole pixel is 1 px from covered ones.
  coverage(cv::Rect(10, 5, 1, 20)).setTo(0);
  EXPECT_NEAR(HoleScore(coverage), 20.0 / (40 * 50), 1e-9);
  // A wide hole scores far more than the same area spread thin (the metric's point).
  cv::Mat block(40, 50, CV_8U, cv::Scalar(255));
  block(cv::Rect(10, 10, 20, 20)).setTo(0);
  cv::Mat lines(40, 50, CV_8U, cv::Scalar(255));
  for (int i = 0; i < 20; ++i) lines(cv::Rect(5 + 2 * i, 10, 1, 20)).setTo(0);
  EXPECT_GT(HoleScore(block), 20 * HoleScore(lines));
  // Nothing covered: the worst score, finite.
  const double none = HoleScore(cv::Mat(40, 50, CV_8U, cv::Scalar(0)));
  EXPECT_NEAR(none, std::pow(std::hypot(50.0, 40.0), 3.0), 1e-6);
}

// A near surface (1 m, red) left of a far one (3 m, blue) with a `gap` px wide hole between them,
// as a camera moving right uncovers background beside a foreground edge.
struct EdgeScene {
  explicit EdgeScene(int gap, int width = 60, int height = 20) {
    colour = cv::Mat(height, width, CV_32FC3, cv::Scalar(255, 0, 0));
    depth = cv::Mat(height, width, CV_32F, cv::Scalar(3.0f));
    colour(cv::Rect(0, 0, 20, height)).setTo(cv::Scalar(0, 0, 255));
    depth(cv::Rect(0, 0, 20, height)).setTo(1.0f);
    known = cv::Mat(height, width, CV_8U, cv::Scalar(255));
    known(cv::Rect(20, 0, gap, height)).setTo(0);
    colour.setTo(cv::Scalar(0, 0, 0), known == 0);
    depth.setTo(0.0f, known == 0);
  }
  cv::Mat colour, depth, known;
};

TEST(FillHolesTest, SmallHolesTakeTheFartherSideInOnePass) {
  EdgeScene scene(5);  // under 6 px: the 7x7 window reaches across it from both sides
  const SoftZ soft_z(2.0, 0.1);
  EXPECT_EQ(cv::countNonZero(SmallHoles(scene.known, 3)), 5 * 20);
  const HoleFillReport report = FillHolesReverseSoftZ(soft_z, 3, 1, &scene.known, &scene.colour, &scene.depth);
  EXPECT_EQ(report.hole_pixels, 100);
  EXPECT_EQ(report.first_pass, 100);
  EXPECT_EQ(report.unfilled, 0);
  for (int y = 0; y < 20; ++y) {
    for (int x = 20; x < 25; ++x) {
      // Within 3 px of the background, the near surface (2 m nearer: weight 0) does not leak in.
      if (x >= 22) {
        ASSERT_LT(cv::norm(scene.colour.at<cv::Vec3f>(y, x) - cv::Vec3f(255, 0, 0)), 1e-3) << x << "," << y;
        ASSERT_NEAR(scene.depth.at<float>(y, x), 3.0f, 1e-5);
      }
      ASSERT_NE(scene.known.at<uint8_t>(y, x), 0);
    }
  }
}

TEST(FillHolesTest, LargeHolesAreNotSmallAndFillRingByRingFromTheBackground) {
  EdgeScene scene(20);
  const SoftZ soft_z(2.0, 0.1);
  EXPECT_EQ(cv::countNonZero(SmallHoles(scene.known, 3)), 0);
  // One pass fills only the rims (3 px from each side).
  cv::Mat known = scene.known.clone(), colour = scene.colour.clone(), depth = scene.depth.clone();
  const HoleFillReport rim = FillHolesReverseSoftZ(soft_z, 3, 1, &known, &colour, &depth);
  EXPECT_EQ(rim.first_pass, 6 * 20);
  EXPECT_EQ(rim.unfilled, 14 * 20);
  for (int y = 0; y < 20; ++y) {
    for (int x = 37; x < 40; ++x) {
      ASSERT_LT(cv::norm(colour.at<cv::Vec3f>(y, x) - cv::Vec3f(255, 0, 0)), 1e-3) << x << "," << y;
    }
  }
  // All passes fill everything. Each ring reads only the ring before it, so the foreground's rim
  // carries on from the left (the preview's limit: large holes are the offline inpainting's job),
  // but where the two fronts meet the background wins, and the right half is background.
  const HoleFillReport all = FillHolesReverseSoftZ(soft_z, 3, 0, &scene.known, &scene.colour, &scene.depth);
  EXPECT_EQ(all.unfilled, 0);
  EXPECT_EQ(all.first_pass + all.later_passes, 400);
  for (int y = 0; y < 20; ++y) {
    for (int x = 30; x < 40; ++x) {
      ASSERT_LT(cv::norm(scene.colour.at<cv::Vec3f>(y, x) - cv::Vec3f(255, 0, 0)), 1e-3) << x << "," << y;
    }
  }
}

TEST(FillHolesTest, NothingKnownLeavesEverythingUnfilled) {
  cv::Mat known(10, 10, CV_8U, cv::Scalar(0));
  cv::Mat colour(10, 10, CV_32FC3, cv::Scalar(0, 0, 0)), depth(10, 10, CV_32F, cv::Scalar(0));
  const HoleFillReport report = FillHolesReverseSoftZ(SoftZ(1.0, 0.1), 3, 0, &known, &colour, &depth);
  EXPECT_EQ(report.unfilled, 100);
}

}  // namespace
}  // namespace px::render
