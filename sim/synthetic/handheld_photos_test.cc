#include "sim/synthetic/handheld_photos.h"

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include "pipeline/io/exif.h"
#include "sim/synthetic/data_paths.h"
#include "tests/testing/temp_dir.h"

namespace px::sim {
namespace {

class HandHeldPhotosTest : public px::testing::TempDirTest {};

TEST_F(HandHeldPhotosTest, PhotosAreJpegsOfTheSizeWithTheirFocalLengthInExif) {
  HandHeldPhotoOptions options;
  options.width = 320;
  options.height = 240;
  options.shots = 3;
  StatusOr<std::vector<std::filesystem::path>> photos =
      WriteHandHeldPhotos(ScenesDir() / "still_life.json", options, dir() / "photos");
  ASSERT_TRUE(photos.ok()) << photos.status().ToString();
  ASSERT_EQ(photos->size(), 3u);
  cv::Mat previous;
  for (const std::filesystem::path& photo : *photos) {
    const cv::Mat image = cv::imread(photo.string());
    ASSERT_FALSE(image.empty()) << photo;
    EXPECT_EQ(image.size(), cv::Size(320, 240));
    StatusOr<ExifInfo> exif = ReadJpegExif(photo);
    ASSERT_TRUE(exif.ok()) << exif.status().ToString();
    EXPECT_NEAR(exif->FocalPx(320, 240), 560.0 * 320 / 640, 0.5) << "the Pop9's field of view at this width";
    if (!previous.empty()) {
      EXPECT_GT(cv::norm(image, previous, cv::NORM_L1) / image.total(), 5.0) << "each shot from its own place";
    }
    previous = image;
  }
}

TEST_F(HandHeldPhotosTest, BadOptionsAreNamedAndWriteNothing) {
  HandHeldPhotoOptions options;
  options.shots = 7;
  StatusOr<std::vector<std::filesystem::path>> photos =
      WriteHandHeldPhotos(ScenesDir() / "still_life.json", options, dir() / "photos");
  ASSERT_FALSE(photos.ok());
  EXPECT_EQ(photos.status().message(), "hand-held photo options: shots = 7 is outside [2, 4]");
  EXPECT_FALSE(std::filesystem::exists(dir() / "photos"));
  EXPECT_FALSE(WriteHandHeldPhotos(dir() / "no_such_scene.json", HandHeldPhotoOptions{}, dir() / "photos").ok());
}

}  // namespace
}  // namespace px::sim
