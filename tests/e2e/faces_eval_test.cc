// `parallax eval faces` on the real labelled photos (faces_dlib_pascalvoc, 18 faces) and the
// simulator's face scenes with the product's detector and the pipeline's default options.
// Bounds: measured recall 15/18 = 0.83 and precision 15/16 = 0.94 (min_neighbors 5, no upscaling
// of 500 px images); before tuning precision was 14/20 = 0.70. The bounds allow one more miss and
// two more false faces than measured on this small set (recall >= 0.75, precision >= 0.80), so a
// change that brings back the old false faces fails.
#include "eval/faces/faces_eval.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

#include "device/face_cascades.h"
#include "eval/faces/sim_face_scenes.h"

namespace px {
namespace {

TEST(FacesEvalTest, PascalVocFacesMeetTheBounds) {
  const std::filesystem::path dir = eval::DlibFacesDir({});
  if (!std::filesystem::exists(dir / "training.xml")) GTEST_SKIP() << "real data absent: " << dir.string();
  auto detector = device::LoadFaceDetector();
  if (!detector.ok()) GTEST_SKIP() << detector.status().message();
  auto result = eval::RunFacesEval(**detector, eval::FacesEvalOptions{});
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  const eval::FaceMatch& t = result->total;
  std::printf(
      "[figures] faces_dlib_pascalvoc: %d faces, %d detections, %d hits at IoU >= 0.5: precision %.2f, "
      "recall %.2f, %.0f ms per image\n",
      t.truth,
      t.detections,
      t.true_positives,
      t.Precision(),
      t.Recall(),
      result->mean_ms);
  EXPECT_EQ(t.truth, 18);
  EXPECT_GE(t.Recall(), 0.75);
  EXPECT_GE(t.Precision(), 0.80);
}

// The 640x480 two-face scene: before tuning the cascades found four faces and the two-largest
// cut dropped the true 55x55 far face for two larger false ones.
TEST(FacesEvalTest, SimFaceScenesHaveTheirFacesAndNoOthers) {
  auto detector = device::LoadFaceDetector();
  if (!detector.ok()) GTEST_SKIP() << detector.status().message();
  auto scenes = eval::RunSimFaceScenes(**detector, FaceDetectionOptions{});
  if (!scenes.ok() && scenes.status().code() == StatusCode::kFailedPrecondition) {
    GTEST_SKIP() << scenes.status().message();
  }
  ASSERT_TRUE(scenes.ok()) << scenes.status().ToString();
  for (const eval::FaceImageResult& scene : *scenes) {
    std::printf("[figures] %s: %d faces, %d detections, %d hits\n",
                scene.file.c_str(),
                scene.match.truth,
                scene.match.detections,
                scene.match.true_positives);
    EXPECT_EQ(scene.match.true_positives, scene.match.truth) << scene.file;
    EXPECT_EQ(scene.match.detections, scene.match.truth) << scene.file;
  }
}

}  // namespace
}  // namespace px
