// The morph's push-in on its subjects (morph_framing.h) on a synthetic pair, as a horizontal
// stereo pair sees it: the textured background moves 6 px to the right between the views, a
// nearer "face" patch 18 px.
#include "pipeline/direct/morph_framing.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <random>

namespace px::direct {
namespace {

constexpr int kWidth = 480, kHeight = 360;
const cv::Rect kFaceInA(200, 100, 60, 70);
constexpr int kBackgroundShiftPx = 6;
constexpr int kFaceShiftPx = 18;

cv::Mat Texture(int width, int height, uint32_t seed) {
  cv::Mat noise(height / 4, width / 4, CV_8UC3);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 255);
  cv::Mat texture;
  cv::resize(noise, texture, cv::Size(width, height), 0, 0, cv::INTER_CUBIC);
  return texture;
}

struct Pair {
  cv::Mat a, b;
};

Pair MovingFacePair() {
  const cv::Mat background = Texture(kWidth + kBackgroundShiftPx, kHeight, 1);
  const cv::Mat face = Texture(kFaceInA.width, kFaceInA.height, 2);
  Pair pair{background(cv::Rect(kBackgroundShiftPx, 0, kWidth, kHeight)).clone(),
            background(cv::Rect(0, 0, kWidth, kHeight)).clone()};
  face.copyTo(pair.a(kFaceInA));
  face.copyTo(pair.b(kFaceInA + cv::Point(kFaceShiftPx, 0)));
  return pair;
}

CameraPath MorphPathWithFace(int width, int height) {
  CameraPath path = BlankPath(PathKind::kMorph, "morph", CameraModel::Pinhole(width, height, width), 15, 2.0);
  path.source_views = {0, 1};
  for (double t : {0.0, 1.0}) {
    CameraKeyframe key;
    key.t = t;
    key.focal_px = width;
    path.keyframes.push_back(key);
  }
  Subject face;
  face.source = "face";
  face.view = 0;
  face.box_px = cv::Rect2d(kFaceInA);
  path.subjects = {face};
  return path;
}

bool Inside(const cv::Rect2d& outer, const cv::Rect2d& inner) { return (outer & inner) == inner; }

TEST(MorphFramingTest, PushesInOnTheFaceAndKeepsItInEveryFrame) {
  const Pair pair = MovingFacePair();
  auto morph = ViewMorph::Create(pair.a, pair.b, MorphOptions{});
  ASSERT_TRUE(morph.ok()) << morph.status().ToString();
  CameraPath path = MorphPathWithFace(kWidth, kHeight);
  DirectOptions options;
  const double zoom = PlanMorphPushIn(**morph, options, &path);
  EXPECT_GT(zoom, 1.3);
  EXPECT_LE(zoom, options.zoom_in + 1e-9);
  ASSERT_TRUE(path.Validate().ok());

  // The face's box follows the flow: at the end it has moved with the patch.
  const cv::Rect2d end_box = MorphSubjectsBoxAt(path, **morph, 1.0);
  EXPECT_NEAR(end_box.x, kFaceInA.x + kFaceShiftPx, 3.0);
  EXPECT_NEAR(end_box.y, kFaceInA.y, 3.0);

  // The first frame shows the whole image; every frame keeps the face; the last is aimed at it.
  const cv::Rect2d first = MorphWindowAt(path, **morph, 0.0, 0.03);
  EXPECT_NEAR(first.width, kWidth, 1e-6);
  EXPECT_NEAR(first.height, kHeight, 1e-6);
  for (int i = 0; i < path.NumFrames(); ++i) {
    const double t = path.FrameTime(i);
    EXPECT_TRUE(Inside(MorphWindowAt(path, **morph, t, 0.03), MorphSubjectsBoxAt(path, **morph, t))) << "frame " << i;
  }
  const cv::Rect2d last = MorphWindowAt(path, **morph, 1.0, 0.03);
  EXPECT_NEAR(last.width, kWidth / zoom, 1e-6);
  const double face_x = end_box.x + 0.5 * end_box.width;
  EXPECT_LT(std::abs(face_x - (last.x + 0.5 * last.width)), 0.05 * kWidth) << "the frame ends on the face";

  // The cut frame is the window at output size: its centre pixel is the window centre's.
  const cv::Mat frame = CutMorphFrame(pair.a, path, **morph, 1.0, 0.03);
  ASSERT_EQ(frame.size(), cv::Size(kWidth, kHeight));
}

TEST(MorphFramingTest, WithoutSubjectsTheWholeFrameStays) {
  const Pair pair = MovingFacePair();
  auto morph = ViewMorph::Create(pair.a, pair.b, MorphOptions{});
  ASSERT_TRUE(morph.ok());
  CameraPath path = MorphPathWithFace(kWidth, kHeight);
  path.subjects.clear();
  EXPECT_EQ(PlanMorphPushIn(**morph, DirectOptions{}, &path), 1.0);
  EXPECT_EQ(path.keyframes.back().focal_px, path.keyframes.front().focal_px);
  const cv::Mat frame = CutMorphFrame(pair.a, path, **morph, 0.5, 0.03);
  cv::Mat difference;
  cv::absdiff(frame, pair.a, difference);
  EXPECT_LT(cv::mean(difference)[0], 1.0) << "zoom 1 at the view's size is the image itself";
}

TEST(MorphFramingTest, AFaceFillingTheFrameLeavesNoRoomToPushIn) {
  const Pair pair = MovingFacePair();
  auto morph = ViewMorph::Create(pair.a, pair.b, MorphOptions{});
  ASSERT_TRUE(morph.ok());
  CameraPath path = MorphPathWithFace(kWidth, kHeight);
  path.subjects[0].box_px = cv::Rect2d(10, 10, kWidth - 20, kHeight - 20);
  EXPECT_EQ(PlanMorphPushIn(**morph, DirectOptions{}, &path), 1.0);
}

TEST(MorphFramingTest, APortraitFrameFromALandscapeMorphStaysOnTheFace) {
  const Pair pair = MovingFacePair();
  auto morph = ViewMorph::Create(pair.a, pair.b, MorphOptions{});
  ASSERT_TRUE(morph.ok());
  CameraPath path = MorphPathWithFace(kWidth, kHeight);
  path.width = 180;  // a 9:16 frame cut from the 4:3 morph: its centred crop spans x 139..341
  path.height = 320;
  path.subjects[0].box_px = cv::Rect2d(380, 100, 60, 70);
  const double zoom = PlanMorphPushIn(**morph, DirectOptions{}, &path);
  EXPECT_GT(zoom, 1.0);
  for (int i = 0; i < path.NumFrames(); ++i) {
    const double t = path.FrameTime(i);
    const cv::Rect2d window = MorphWindowAt(path, **morph, t, 0.03);
    EXPECT_NEAR(window.width / window.height, 180.0 / 320.0, 1e-6);
    EXPECT_GE(window.x, 0);
    EXPECT_LE(window.x + window.width, kWidth + 1e-6);
    EXPECT_TRUE(Inside(window, MorphSubjectsBoxAt(path, **morph, t))) << "frame " << i;
  }
  EXPECT_EQ(CutMorphFrame(pair.a, path, **morph, 0.3, 0.03).size(), cv::Size(180, 320));
}

}  // namespace
}  // namespace px::direct
