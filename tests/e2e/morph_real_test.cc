// The two-view morph (paper 4.5) on real pairs with a face from ../shared/data: the stereo pair
// (stereo_face) and the hand-held portrait (handheld/ddd_seattle_portrait_2views). Checks that
// the correspondences hold and that the detected face stays wholly inside every morph frame;
// prints the morph's figures.
#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "device/face_cascades.h"
#include "pipeline/direct/view_morph.h"
#include "sim/synthetic/data_paths.h"

namespace px {
namespace {

// `min_consistent`: the share of flow that must agree both ways (measured: 57 % on the stereo
// pair; 29 % on the hand-held pair, whose wide baseline and head turn leave much seen once, so
// the pipeline, which morphs from 50 %, pans and zooms over it instead).
void CheckPair(const std::string& folder, const std::string& a_name, const std::string& b_name, double min_consistent) {
  const std::filesystem::path dir = sim::SharedDataDir() / folder;
  if (!std::filesystem::exists(dir)) GTEST_SKIP() << "real data absent: " << dir.string();
  auto detector = device::LoadFaceDetector();
  if (!detector.ok()) GTEST_SKIP() << detector.status().message();
  cv::Mat a = cv::imread((dir / a_name).string()), b = cv::imread((dir / b_name).string());
  ASSERT_FALSE(a.empty() || b.empty()) << dir.string();
  // Working size: at most 960 px wide (the morph computes flow at 640 anyway).
  const double scale = std::min(1.0, 960.0 / a.cols);
  cv::resize(a, a, cv::Size(), scale, scale, cv::INTER_AREA);
  cv::resize(b, b, a.size(), 0, 0, cv::INTER_AREA);
  auto morph = direct::ViewMorph::Create(a, b, direct::MorphOptions{});
  ASSERT_TRUE(morph.ok()) << morph.status().ToString();
  const direct::MorphReport& r = (*morph)->report();
  EXPECT_GT(r.consistent_fraction, min_consistent);
  EXPECT_LT(r.mean_abs_diff_warped, r.mean_abs_diff_unwarped);
  std::vector<direct::FaceBox> faces = (*detector)->Detect(a, FaceDetectionOptions{});
  ASSERT_FALSE(faces.empty()) << "no face found in " << a_name;
  const cv::Rect2d face = faces.front().box;
  double min_margin_px = 1e9;
  for (int i = 0; i <= 10; ++i) {
    const double t = i / 10.0;
    for (const cv::Point2d corner :
         {face.tl(), face.br(), cv::Point2d(face.x + face.width, face.y), cv::Point2d(face.x, face.y + face.height)}) {
      const cv::Point2d p = (*morph)->TrackFromA(corner, t);
      min_margin_px = std::min({min_margin_px, p.x, p.y, a.cols - 1 - p.x, a.rows - 1 - p.y});
    }
  }
  EXPECT_GE(min_margin_px, 0) << "the face leaves the frame";
  std::printf(
      "[figures] %s: %dx%d, %.0f%% consistent, epipolar %s (%.0f%% inliers, median %.2f px), %.1f%% moving; "
      "mean |a-b| %.1f unwarped, %.1f warped; face %.0fx%.0f, min margin %.0f px; %.0f ms\n",
      folder.c_str(),
      a.cols,
      a.rows,
      100 * r.consistent_fraction,
      r.epipolar ? "yes" : "no",
      100 * r.fundamental_inliers,
      r.median_epipolar_px,
      100 * r.moving_fraction,
      r.mean_abs_diff_unwarped,
      r.mean_abs_diff_warped,
      face.width,
      face.height,
      min_margin_px,
      r.ms);
}

TEST(MorphRealTest, StereoFace) {
  CheckPair("stereo_face/ddd_frame31_stereo", "frame_31_left.jpg", "frame_31_right.jpg", 0.5);
}

TEST(MorphRealTest, HandHeldPortrait) {
  CheckPair("handheld/ddd_seattle_portrait_2views", "P1170063.JPG", "P1170067.JPG", 0.2);
}

}  // namespace
}  // namespace px
