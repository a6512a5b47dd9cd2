// Lattice detection on frames drawn here (textured tiles on a dark sensor), its options and its
// argument errors. The simulated-camera and real-data cases are in eval/lattice.
#include "pipeline/lattice/lattice_detector.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

namespace px {
namespace {

// A lattice of 200x150 tiles (one random texture, blurred, seen shifted by each column) on a dark
// sensor with 12 px gaps.
struct DrawnFrame {
  cv::Mat bgr;
  LatticeLayout truth;
};

DrawnFrame DrawLattice(int rows, int cols) {
  DrawnFrame f;
  f.truth = LatticeLayout::Regular(rows, cols, 200, 150, 12, TileOrientation::kRotated180);
  f.bgr = cv::Mat(f.truth.sensor_height, f.truth.sensor_width, CV_8UC3, cv::Scalar::all(10));
  // One textured scene, each tile seeing it a few pixels further along (the lenses' parallax).
  cv::RNG rng(7);
  cv::Mat scene(f.truth.tiles[0].rect.height, f.truth.tiles[0].rect.width + 4 * cols, CV_8UC3);
  rng.fill(scene, cv::RNG::UNIFORM, cv::Scalar::all(60), cv::Scalar::all(220));
  cv::GaussianBlur(scene, scene, cv::Size(0, 0), 3.0);
  for (const Tile& t : f.truth.tiles) {
    scene(cv::Rect(4 * t.col, 0, t.rect.width, t.rect.height)).copyTo(f.bgr(t.rect));
  }
  return f;
}

TEST(LatticeDetectorTest, FindsDrawnLatticesExactly) {
  for (const auto& [rows, cols] : {std::pair(2, 2), std::pair(3, 3), std::pair(4, 5)}) {
    const DrawnFrame f = DrawLattice(rows, cols);
    StatusOr<LatticeDetection> d = DetectLattice(f.bgr, LatticeOptions());
    ASSERT_TRUE(d.ok()) << rows << "x" << cols << ": " << d.status().message();
    ASSERT_EQ(d->layout.rows, rows);
    ASSERT_EQ(d->layout.cols, cols);
    for (int i = 0; i < f.truth.NumViews(); ++i) {
      const cv::Rect a = f.truth.tiles[i].rect, b = d->layout.tiles[i].rect;
      EXPECT_LE(std::abs(a.x - b.x) + std::abs(a.y - b.y) + std::abs(a.width - b.width) + std::abs(a.height - b.height),
                2)
          << "tile " << i << ": " << b << " against " << a;
      EXPECT_EQ(d->layout.tiles[i].orientation, TileOrientation::kRotated180);
    }
    EXPECT_FALSE(d->report.evidence.empty());
    EXPECT_NE(d->report.Summary().find("dark gaps"), std::string::npos) << d->report.Summary();
  }
}

TEST(LatticeDetectorTest, ExpectedCountsThatTheFrameDoesNotShowAreRefused) {
  const DrawnFrame f = DrawLattice(3, 3);
  LatticeOptions options;
  options.rows = 4;
  options.cols = 4;
  StatusOr<LatticeDetection> d = DetectLattice(f.bgr, options);
  ASSERT_FALSE(d.ok());
  EXPECT_EQ(d.status().code(), StatusCode::kNotFound);
  EXPECT_NE(d.status().message().find("4"), std::string::npos) << d.status().message();
}

TEST(LatticeDetectorTest, PriorOfAnotherAspectRatioIsAnInvalidArgument) {
  const DrawnFrame f = DrawLattice(3, 3);
  const LatticeLayout prior = LatticeLayout::Regular(3, 3, 300, 100, 12);
  StatusOr<LatticeDetection> d = DetectLattice(f.bgr, LatticeOptions(), &prior);
  ASSERT_FALSE(d.ok());
  EXPECT_EQ(d.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(d.status().message().find("aspect"), std::string::npos) << d.status().message();
}

TEST(LatticeDetectorTest, PriorAtHalfResolutionIsScaled) {
  const DrawnFrame f = DrawLattice(3, 3);
  cv::Mat half;
  cv::resize(f.bgr, half, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
  StatusOr<LatticeDetection> d = DetectLattice(half, LatticeOptions(), &f.truth);
  ASSERT_TRUE(d.ok()) << d.status().message();
  EXPECT_TRUE(d->report.used_prior);
  EXPECT_EQ(d->layout.sensor_width, half.cols);
  EXPECT_NEAR(d->layout.tiles[4].rect.x, f.truth.tiles[4].rect.x / 2.0, 1.5);
  EXPECT_LT(d->report.max_prior_shift_px, 1.5);
}

TEST(LatticeDetectorTest, TooSmallFrameAndBadOptionsNameTheValue) {
  StatusOr<LatticeDetection> d = DetectLattice(cv::Mat(20, 20, CV_8UC3, cv::Scalar::all(0)), LatticeOptions());
  ASSERT_FALSE(d.ok());
  EXPECT_NE(d.status().message().find("20x20"), std::string::npos) << d.status().message();
  LatticeOptions options;
  options.min_gap_z = 1;
  EXPECT_NE(options.Validate().message().find("min_gap_z = 1"), std::string::npos) << options.Validate().message();
  options = LatticeOptions();
  options.min_confidence = 2;
  EXPECT_NE(options.Validate().message().find("min_confidence = 2"), std::string::npos);
  options = LatticeOptions();
  options.rows = 9;
  EXPECT_NE(options.Validate().message().find("rows = 9"), std::string::npos);
}

}  // namespace
}  // namespace px
