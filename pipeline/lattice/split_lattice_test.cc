#include "pipeline/lattice/split_lattice.h"

#include <gtest/gtest.h>

#include <cmath>

namespace px {
namespace {

// An upright tile whose every pixel encodes where it is: B = x, G = y, R = view id. Any wrong
// crop, flip or rotation shows up as a mismatch at some pixel.
cv::Mat CodedTile(int width, int height, int view_id) {
  cv::Mat tile(height, width, CV_8UC3);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      tile.at<cv::Vec3b>(y, x) = cv::Vec3b(static_cast<uchar>(x), static_cast<uchar>(y), static_cast<uchar>(view_id));
    }
  }
  return tile;
}

// Where the upright pixel (x, y) lies inside the stored tile, written out per orientation
// (independently of the code under test, which uses cv::rotate / cv::flip).
cv::Point StoredPosition(int x, int y, int width, int height, TileOrientation orientation) {
  switch (orientation) {
    case TileOrientation::kUpright:
      return {x, y};
    case TileOrientation::kRotated180:
      return {width - 1 - x, height - 1 - y};
    case TileOrientation::kMirroredX:
      return {width - 1 - x, y};
    case TileOrientation::kMirroredY:
      return {x, height - 1 - y};
  }
  return {x, y};
}

// A sensor frame with grey borders holding each view's coded tile, stored per its orientation.
cv::Mat RenderSensor(const LatticeLayout& layout) {
  cv::Mat sensor(layout.sensor_height, layout.sensor_width, CV_8UC3, cv::Scalar(17, 17, 17));
  for (int id = 0; id < layout.NumViews(); ++id) {
    const Tile& tile = layout.tiles[id];
    const cv::Mat upright = CodedTile(tile.rect.width, tile.rect.height, id);
    for (int y = 0; y < tile.rect.height; ++y) {
      for (int x = 0; x < tile.rect.width; ++x) {
        const cv::Point s = StoredPosition(x, y, tile.rect.width, tile.rect.height, tile.orientation);
        sensor.at<cv::Vec3b>(tile.rect.y + s.y, tile.rect.x + s.x) = upright.at<cv::Vec3b>(y, x);
      }
    }
  }
  return sensor;
}

class SplitLatticeOrientationTest : public testing::TestWithParam<TileOrientation> {};

TEST_P(SplitLatticeOrientationTest, TilesComeOutUprightInViewOrder) {
  const LatticeLayout layout = LatticeLayout::Regular(3, 3, 40, 30, 4, GetParam());
  const cv::Mat sensor = RenderSensor(layout);
  StatusOr<std::vector<cv::Mat>> tiles = SplitLattice(sensor, layout);
  ASSERT_TRUE(tiles.ok()) << tiles.status().ToString();
  ASSERT_EQ(tiles->size(), 9u);
  for (int id = 0; id < 9; ++id) {
    const cv::Mat& tile = (*tiles)[id];
    ASSERT_EQ(tile.type(), CV_8UC3);
    ASSERT_EQ(tile.size(), cv::Size(40, 30));
    const cv::Mat expected = CodedTile(40, 30, id);
    EXPECT_EQ(cv::norm(tile, expected, cv::NORM_INF), 0.0) << "view " << id;
  }
}

INSTANTIATE_TEST_SUITE_P(AllOrientations,
                         SplitLatticeOrientationTest,
                         testing::Values(TileOrientation::kUpright,
                                         TileOrientation::kRotated180,
                                         TileOrientation::kMirroredX,
                                         TileOrientation::kMirroredY),
                         [](const testing::TestParamInfo<TileOrientation>& param_info) {
                           return std::string(TileOrientationName(param_info.param));
                         });

TEST(SplitLatticeTest, MixedOrientationsAndIrregularTiles) {
  LatticeLayout layout;
  layout.rows = 1;
  layout.cols = 3;
  layout.sensor_width = 100;
  layout.sensor_height = 50;
  layout.tiles = {{0, 0, cv::Rect(0, 0, 30, 20), TileOrientation::kRotated180},
                  {0, 1, cv::Rect(31, 5, 25, 40), TileOrientation::kUpright},
                  {0, 2, cv::Rect(60, 10, 40, 40), TileOrientation::kMirroredY}};
  const cv::Mat sensor = RenderSensor(layout);
  StatusOr<std::vector<cv::Mat>> tiles = SplitLattice(sensor, layout);
  ASSERT_TRUE(tiles.ok()) << tiles.status().ToString();
  ASSERT_EQ(tiles->size(), 3u);
  for (int id = 0; id < 3; ++id) {
    const cv::Rect& rect = layout.tiles[id].rect;
    EXPECT_EQ(cv::norm((*tiles)[id], CodedTile(rect.width, rect.height, id), cv::NORM_INF), 0.0) << "view " << id;
  }
}

// A rotated tile whose content is linear in its own coordinates (B = 3u, G = 5v, R = id): bilinear
// resampling reproduces a linear function exactly, so the cut tile must match to rounding. The
// sensor is drawn by inverting the rotation here, written out independently of SensorFromTile.
TEST(SplitLatticeTest, RotatedTilesAreResampledUpright) {
  LatticeLayout layout;
  layout.rows = 1;
  layout.cols = 2;
  layout.sensor_width = 160;
  layout.sensor_height = 80;
  layout.tiles = {{0, 0, cv::Rect(10, 12, 50, 40), TileOrientation::kUpright, 2.0},
                  {0, 1, cv::Rect(90, 15, 60, 44), TileOrientation::kRotated180, -1.5}};
  cv::Mat sensor(layout.sensor_height, layout.sensor_width, CV_8UC3, cv::Scalar(9, 9, 9));
  for (int id = 0; id < 2; ++id) {
    const Tile& tile = layout.tiles[id];
    const double a = tile.rotation_deg * CV_PI / 180, cx = tile.rect.x + (tile.rect.width - 1) / 2.0,
                 cy = tile.rect.y + (tile.rect.height - 1) / 2.0;
    for (int y = 0; y < sensor.rows; ++y) {
      for (int x = 0; x < sensor.cols; ++x) {
        // Turn the sensor offset back by -a (clockwise-positive angles, y down).
        const double du = std::cos(a) * (x - cx) + std::sin(a) * (y - cy);
        const double dv = -std::sin(a) * (x - cx) + std::cos(a) * (y - cy);
        const double u = du + (tile.rect.width - 1) / 2.0, v = dv + (tile.rect.height - 1) / 2.0;
        if (u < -0.5 || v < -0.5 || u > tile.rect.width - 0.5 || v > tile.rect.height - 0.5) continue;
        sensor.at<cv::Vec3b>(y, x) =
            cv::Vec3b(cv::saturate_cast<uchar>(3 * u), cv::saturate_cast<uchar>(5 * v), static_cast<uchar>(id));
      }
    }
  }
  StatusOr<std::vector<cv::Mat>> tiles = SplitLattice(sensor, layout);
  ASSERT_TRUE(tiles.ok()) << tiles.status().ToString();
  for (int id = 0; id < 2; ++id) {
    const Tile& tile = layout.tiles[id];
    const cv::Mat& upright = (*tiles)[id];
    ASSERT_EQ(upright.size(), tile.rect.size());
    int checked = 0;
    for (int v = 1; v < tile.rect.height - 1; ++v) {
      for (int u = 1; u < tile.rect.width - 1; ++u) {
        const cv::Point s = StoredPosition(u, v, tile.rect.width, tile.rect.height, tile.orientation);
        const cv::Vec3b got = upright.at<cv::Vec3b>(v, u);
        ASSERT_NEAR(got[0], 3 * s.x, 1.01) << "view " << id << " at " << u << "," << v;
        ASSERT_NEAR(got[1], 5 * s.y, 1.01) << "view " << id << " at " << u << "," << v;
        ASSERT_EQ(got[2], id);
        ++checked;
      }
    }
    EXPECT_GT(checked, 1000);
  }
}

TEST(SplitLatticeTest, TilesOwnTheirPixels) {
  const LatticeLayout layout = LatticeLayout::Regular(2, 2, 20, 10, 2);
  cv::Mat sensor = RenderSensor(layout);
  StatusOr<std::vector<cv::Mat>> tiles = SplitLattice(sensor, layout);
  ASSERT_TRUE(tiles.ok());
  sensor.setTo(cv::Scalar(255, 255, 255));  // the next capture reuses the buffer
  EXPECT_EQ(cv::norm((*tiles)[3], CodedTile(20, 10, 3), cv::NORM_INF), 0.0);
}

TEST(SplitLatticeTest, WrongSensorSizeNamesBothSizes) {
  LatticeLayout layout = LatticeLayout::Regular(3, 3, 640, 480, 16);
  ASSERT_EQ(layout.sensor_width, 1984);
  ASSERT_EQ(layout.sensor_height, 1504);
  const cv::Mat frame(1080, 1920, CV_8UC3, cv::Scalar(0, 0, 0));
  StatusOr<std::vector<cv::Mat>> tiles = SplitLattice(frame, layout);
  ASSERT_FALSE(tiles.ok());
  EXPECT_EQ(tiles.status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(tiles.status().message(), "sensor frame is 1920x1080, lattice expects 1984x1504");
}

TEST(SplitLatticeTest, RejectsNonBgrAndEmptyFrames) {
  const LatticeLayout layout = LatticeLayout::Regular(1, 2, 8, 8, 1);
  const cv::Mat gray(layout.sensor_height, layout.sensor_width, CV_8UC1, cv::Scalar(0));
  StatusOr<std::vector<cv::Mat>> from_gray = SplitLattice(gray, layout);
  ASSERT_FALSE(from_gray.ok());
  EXPECT_NE(from_gray.status().message().find("CV_8UC3"), std::string::npos) << from_gray.status().message();
  EXPECT_FALSE(SplitLattice(cv::Mat(), layout).ok());
}

TEST(SplitLatticeTest, RejectsInvalidLayout) {
  LatticeLayout layout = LatticeLayout::Regular(1, 2, 8, 8, 1);
  layout.tiles[1].rect.x = 2;  // now overlaps tile 0
  const cv::Mat frame(layout.sensor_height, layout.sensor_width, CV_8UC3, cv::Scalar(0, 0, 0));
  StatusOr<std::vector<cv::Mat>> tiles = SplitLattice(frame, layout);
  ASSERT_FALSE(tiles.ok());
  EXPECT_NE(tiles.status().message().find("overlap"), std::string::npos) << tiles.status().message();
}

}  // namespace
}  // namespace px
