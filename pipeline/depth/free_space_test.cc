#include "pipeline/depth/free_space.h"

#include <gtest/gtest.h>

#include <initializer_list>
#include <vector>

namespace px::depth {
namespace {

constexpr int kWidth = 96, kHeight = 64, kBlock = 16;  // 6 x 4 segments of 16 x 16 pixels
constexpr double kFocal = 80.0, kWallM = 2.0;

// A reference view at the origin and `others` cameras beside it along x, every other view seeing
// a wall kWallM away everywhere.
struct Scene {
  std::vector<View> views;
  std::vector<cv::Mat> depth_m;
  std::vector<int> others;
};

Scene WallScene(int others, double spacing_m = 0.1) {
  Scene scene;
  for (int i = 0; i <= others; ++i) {
    View view;
    view.id = ViewId{i};
    view.camera = CameraModel::Pinhole(kWidth, kHeight, kFocal);
    view.image = cv::Mat(kHeight, kWidth, CV_8UC3, cv::Scalar(128, 128, 128));
    // Camera centre at x = spacing_m i: cam_from_world translates by -centre.
    view.cam_from_world = Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-spacing_m * i, 0, 0));
    scene.views.push_back(view);
    scene.depth_m.push_back(i == 0 ? cv::Mat() : cv::Mat(kHeight, kWidth, CV_32F, cv::Scalar(kWallM)));
    if (i > 0) scene.others.push_back(i);
  }
  return scene;
}

// The reference's segments, each fronto-parallel on the wall with confidence 0.5.
SegmentImage BlockSegments() {
  SegmentImage image;
  image.labels = cv::Mat(kHeight, kWidth, CV_32S);
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) image.labels.at<int>(y, x) = (y / kBlock) * (kWidth / kBlock) + x / kBlock;
  }
  const int count = (kWidth / kBlock) * (kHeight / kBlock);
  image.planes.assign(count, InversePlane{0, 0, 1.0 / kWallM});
  image.confidence.assign(count, 0.5f);
  return image;
}

constexpr int kMiddle = 1 * (kWidth / kBlock) + 2;  // a segment away from the image border

// Segments `floating` of BlockSegments() put at `depth_m` with `confidence`.
void Float(std::initializer_list<int> floating, double depth_m, float confidence, SegmentImage* image) {
  for (int s : floating) {
    image->planes[s] = InversePlane{0, 0, 1.0 / depth_m};
    image->confidence[s] = confidence;
  }
}

FreeSpaceStats Replane(const Scene& scene, SegmentImage* image) {
  return ReplaneSeenThroughSegments(scene.views, scene.depth_m, 0, scene.others, FreeSpaceOptions(), image);
}

TEST(FreeSpaceTest, AWeakSegmentFloatingInFrontOfWhatTheOthersSeeTakesItsNeighboursPlane) {
  const Scene scene = WallScene(2);
  SegmentImage image = BlockSegments();
  Float({kMiddle}, 0.5, 0.03f, &image);  // 0.5 m: both other views see the wall through it
  const FreeSpaceStats stats = Replane(scene, &image);
  EXPECT_EQ(stats.contradicted, 1);
  EXPECT_EQ(stats.replaned, 1);
  EXPECT_NEAR(image.planes[kMiddle].At(40, 24), 1.0 / kWallM, 1e-9);
}

TEST(FreeSpaceTest, AWellSupportedSegmentKeepsItsPlane) {
  const Scene scene = WallScene(2);
  SegmentImage image = BlockSegments();
  Float({kMiddle}, 0.5, 0.6f, &image);  // the matcher was sure: the other views' depth may be the wrong one
  const FreeSpaceStats stats = Replane(scene, &image);
  EXPECT_EQ(stats.contradicted, 0);
  EXPECT_NEAR(image.planes[kMiddle].c, 1.0 / 0.5, 1e-9);
}

TEST(FreeSpaceTest, ASegmentBehindWhatTheOthersSeeIsNotContradicted) {
  const Scene scene = WallScene(2);
  SegmentImage image = BlockSegments();
  Float({kMiddle}, 6.0, 0.03f, &image);  // behind the wall: hidden from the others, not seen through
  const FreeSpaceStats stats = Replane(scene, &image);
  EXPECT_EQ(stats.contradicted, 0);
  EXPECT_NEAR(image.planes[kMiddle].c, 1.0 / 6.0, 1e-9);
}

TEST(FreeSpaceTest, ASegmentThatMatchesNothingInColourKeepsItsPlane) {
  Scene scene = WallScene(2);
  // A subject that moved between the shots: the reference has it in front of the wall, the
  // others see the wall there, and no plane carries its colour into them.
  scene.views[0].image(cv::Rect(32, 16, kBlock, kBlock)).setTo(cv::Scalar(40, 40, 220));
  SegmentImage image = BlockSegments();
  Float({kMiddle}, 0.5, 0.03f, &image);
  const FreeSpaceStats stats = Replane(scene, &image);
  EXPECT_EQ(stats.contradicted, 1);
  EXPECT_EQ(stats.replaned, 0);
  EXPECT_NEAR(image.planes[kMiddle].c, 1.0 / 0.5, 1e-9);
}

TEST(FreeSpaceTest, OneViewOfThreeSeeingThroughIsNotAMajority) {
  Scene scene = WallScene(3, 0.05);  // close enough that the segment lands inside all three
  // Two of the three other views see something at 0.5 m where the floating segment lands in
  // them: they confirm it rather than see through it.
  SegmentImage image = BlockSegments();
  Float({kMiddle}, 0.5, 0.03f, &image);
  for (int k : {2, 3}) scene.depth_m[k].setTo(0.5);
  const FreeSpaceStats stats = Replane(scene, &image);
  EXPECT_EQ(stats.contradicted, 0);
  EXPECT_NEAR(image.planes[kMiddle].c, 1.0 / 0.5, 1e-9);
}

TEST(FreeSpaceTest, AFloatingClusterIsReplanedFromItsEdgeInwards) {
  const Scene scene = WallScene(2);
  SegmentImage image = BlockSegments();
  // Three weak segments in a row float together; only the outer two touch the wall's segments.
  Float({kMiddle - 1, kMiddle, kMiddle + 1}, 0.5, 0.03f, &image);
  // The row above and below as well, so the middle one's only settled neighbours are re-planed ones.
  Float({kMiddle - 6, kMiddle + 6}, 0.5, 0.03f, &image);
  const FreeSpaceStats stats = Replane(scene, &image);
  EXPECT_EQ(stats.contradicted, 5);
  EXPECT_EQ(stats.replaned, 5);
  for (int s : {kMiddle - 6, kMiddle - 1, kMiddle, kMiddle + 1, kMiddle + 6})
    EXPECT_NEAR(image.planes[s].c, 1.0 / kWallM, 1e-9) << "segment " << s;
}

}  // namespace
}  // namespace px::depth
