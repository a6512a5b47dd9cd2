// Photos as a recording (import_images.h): order, pixels, sizes, the EXIF focal length of real
// phone photos (../shared/data/handheld, skipped without it), and errors that name the file.
#include "capture/import_images.h"

#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "capture/recording_test_util.h"
#include "sim/synthetic/data_paths.h"
#include "sim/synthetic/exif_jpeg.h"

namespace px {
namespace {

using capture::testing::GradientNoiseBgr;
using capture::testing::ScratchDir;

std::filesystem::path WriteImage(const std::filesystem::path& path, const cv::Mat& bgr) {
  EXPECT_TRUE(cv::imwrite(path.string(), bgr)) << path;
  return path;
}

TEST(ImportImagesTest, FoldersAreSortedFilesKeepTheirOrderAndPixelsComeThrough) {
  ScratchDir dir;
  std::filesystem::create_directories(dir.path() / "shots");
  const cv::Mat first = GradientNoiseBgr(64, 48, 1), second = GradientNoiseBgr(64, 48, 2);
  WriteImage(dir.path() / "shots" / "b.png", second);
  WriteImage(dir.path() / "shots" / "a.PNG", first);
  WriteImage(dir.path() / "shots" / "c.jpg", GradientNoiseBgr(80, 60, 3));
  { std::ofstream(dir.path() / "shots" / "notes.txt") << "not a photo"; }
  const std::filesystem::path extra = WriteImage(dir.path() / "extra.jpeg", GradientNoiseBgr(64, 48, 4));

  StatusOr<std::vector<std::filesystem::path>> files = ListImages({extra, dir.path() / "shots"});
  ASSERT_TRUE(files.ok()) << files.status().ToString();
  ASSERT_EQ(files->size(), 4u);
  EXPECT_EQ((*files)[0].filename(), "extra.jpeg");
  EXPECT_EQ((*files)[1].filename(), "a.PNG");  // 'a' < 'b' < 'c', text files left out
  EXPECT_EQ((*files)[3].filename(), "c.jpg");

  std::vector<std::string> warnings;
  StatusOr<Recording> recording = RecordingFromImages(*files, &warnings);
  ASSERT_TRUE(recording.ok()) << recording.status().ToString();
  EXPECT_EQ(recording->source.kind, FrameSetKind::kImageSet);
  EXPECT_EQ(recording->frames.kind, FrameSetKind::kImageSet);
  ASSERT_EQ(recording->frames.frames.size(), 4u);
  const Frame& a = recording->frames.frames[1];
  EXPECT_EQ(a.sequence, 1u);
  EXPECT_EQ(a.image.format, PixelFormat::kRgb888);
  EXPECT_EQ(recording->frames.frames[3].image.width, 80);
  // A PNG's pixels exactly, in RGB order.
  StatusOr<cv::Mat> decoded = ToBgr(a.image);
  ASSERT_TRUE(decoded.ok());
  EXPECT_EQ(cv::norm(*decoded, first, cv::NORM_INF), 0);
  // JPEGs written by OpenCV carry no EXIF focal length: unknown, to be self-calibrated.
  EXPECT_EQ(recording->frames.frames[0].focal_length_px, 0);

  // The recording writes and reads back as the daemon's would.
  ASSERT_TRUE(WriteRecording(dir.path() / "recording", *recording).ok());
  StatusOr<Recording> read = ReadRecording(dir.path() / "recording");
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  EXPECT_EQ(read->frames.frames.size(), 4u);
}

TEST(ImportImagesTest, ErrorsNameTheFile) {
  ScratchDir dir;
  const std::filesystem::path good = WriteImage(dir.path() / "good.png", GradientNoiseBgr(32, 24, 1));
  { std::ofstream(dir.path() / "broken.jpg") << "these bytes are no JPEG"; }
  { std::ofstream(dir.path() / "readme.txt") << "text"; }
  std::filesystem::create_directories(dir.path() / "empty");

  StatusOr<std::vector<std::filesystem::path>> missing = ListImages({dir.path() / "nowhere.jpg"});
  EXPECT_EQ(missing.status().code(), StatusCode::kNotFound);
  EXPECT_NE(missing.status().message().find("nowhere.jpg"), std::string::npos);
  StatusOr<std::vector<std::filesystem::path>> text = ListImages({dir.path() / "readme.txt"});
  EXPECT_EQ(text.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(text.status().message().find("readme.txt: not a JPEG, PNG, MPO, GIF or WebP"), std::string::npos);
  StatusOr<std::vector<std::filesystem::path>> empty = ListImages({dir.path() / "empty"});
  EXPECT_EQ(empty.status().code(), StatusCode::kNotFound);

  std::vector<std::string> warnings;
  StatusOr<Recording> broken = RecordingFromImages({good, dir.path() / "broken.jpg"}, &warnings);
  EXPECT_EQ(broken.status().code(), StatusCode::kDataLoss);
  EXPECT_NE(broken.status().message().find("broken.jpg: cannot be decoded"), std::string::npos);
}

// One photo alone is one viewpoint: a lattice of views in it, found blind when processed, and a
// warning says so; the same photo in a folder of its own too.
TEST(ImportImagesTest, OnePhotoAloneIsALatticeFoundBlind) {
  ScratchDir dir;
  const std::filesystem::path good = WriteImage(dir.path() / "good.png", GradientNoiseBgr(32, 24, 1));
  std::vector<std::string> warnings;
  StatusOr<Recording> one = RecordingFromImages({good}, &warnings);
  ASSERT_TRUE(one.ok()) << one.status().ToString();
  EXPECT_EQ(one->frames.kind, FrameSetKind::kLatticeFrame);
  ASSERT_TRUE(one->source.lattice.has_value());
  EXPECT_EQ(one->source.lattice->rows, 0);  // found blind
  ASSERT_EQ(one->frames.frames.size(), 1u);
  ASSERT_FALSE(warnings.empty());
  EXPECT_NE(warnings.back().find("one photo"), std::string::npos) << warnings.back();
  std::filesystem::create_directories(dir.path() / "alone");
  std::filesystem::copy_file(good, dir.path() / "alone" / "scan.png");
  StatusOr<Recording> alone = RecordingFromFolder(dir.path() / "alone", {dir.path() / "alone" / "scan.png"}, &warnings);
  ASSERT_TRUE(alone.ok()) << alone.status().ToString();
  EXPECT_EQ(alone->frames.kind, FrameSetKind::kLatticeFrame);
}

// A camera's JPEG with EXIF: its focal length in pixels comes through.
TEST(ImportImagesTest, AJpegsExifFocalLengthComesThrough) {
  ScratchDir dir;
  const cv::Mat bgr = GradientNoiseBgr(96, 64, 5);
  std::vector<uint8_t> jpeg;
  ASSERT_TRUE(cv::imencode(".jpg", bgr, jpeg));
  const std::vector<uint8_t> with_exif = px::sim::WithExifFocalLength(jpeg, 140.0, 96, 64);
  {
    std::ofstream(dir.path() / "a.jpg", std::ios::binary)
        .write(reinterpret_cast<const char*>(with_exif.data()), static_cast<std::streamsize>(with_exif.size()));
  }
  const std::filesystem::path b = WriteImage(dir.path() / "b.png", bgr);
  std::vector<std::string> warnings;
  StatusOr<Recording> recording = RecordingFromImages({dir.path() / "a.jpg", b}, &warnings);
  ASSERT_TRUE(recording.ok()) << recording.status().ToString();
  EXPECT_NEAR(recording->frames.frames[0].focal_length_px, 140.0, 0.01);
  EXPECT_NE(recording->frames.frames[0].focal_length_source.find("EXIF"), std::string::npos);
  EXPECT_EQ(recording->frames.frames[1].focal_length_px, 0);  // a PNG has none
}

// The real photobooth's folder holds its wigglegram twice (rectified with a ChArUco calibration,
// and not): the capture is the first by name, four views, not eight from two geometries.
TEST(ImportImagesTest, TheRealPhotoboothFolderIsItsCalibratedWigglegram) {
  const std::filesystem::path set = sim::SharedDataDir() / "multicam" / "photobooth_pi_4cam_person";
  if (!std::filesystem::exists(set)) GTEST_SKIP() << "photobooth wigglegrams absent: " << set.string();
  StatusOr<std::vector<std::filesystem::path>> files = ListImages({set});
  ASSERT_TRUE(files.ok()) << files.status().ToString();
  std::vector<std::string> warnings;
  StatusOr<Recording> recording = RecordingFromFolder(set, *files, &warnings);
  ASSERT_TRUE(recording.ok()) << recording.status().ToString();
  EXPECT_EQ(recording->frames.frames.size(), 4u);
  const std::string all = [&] {
    std::string text;
    for (const std::string& warning : warnings) text += warning + "\n";
    return text;
  }();
  EXPECT_NE(all.find("wigglegram-example-charuco-calibrated.webp, is taken, and "
                     "wigglegram-example-charuco-not-calibrated.webp (4 views) left out"),
            std::string::npos)
      << all;
}

// Real phone photos: the focal length in pixels from the EXIF 35 mm equivalent.
TEST(ImportImagesTest, PhonePhotosCarryTheirExifFocalLength) {
  const std::filesystem::path set = sim::SharedDataDir() / "handheld" / "kpankov_office_4views";
  if (!std::filesystem::exists(set)) GTEST_SKIP() << "hand-held photos absent: " << set.string();
  StatusOr<std::vector<std::filesystem::path>> files = ListImages({set});
  ASSERT_TRUE(files.ok()) << files.status().ToString();
  std::vector<std::string> warnings;
  StatusOr<Recording> recording = RecordingFromImages(*files, &warnings);
  ASSERT_TRUE(recording.ok()) << recording.status().ToString();
  ASSERT_EQ(recording->frames.frames.size(), 4u);
  for (const Frame& frame : recording->frames.frames) {
    EXPECT_EQ(frame.image.width, 640);
    EXPECT_EQ(frame.image.height, 640);
    // The 35 mm equivalent focal length over the image's diagonal: ~816 px for these 640x640.
    EXPECT_NEAR(frame.focal_length_px, 816, 20);
    EXPECT_NE(frame.focal_length_source.find("EXIF"), std::string::npos);
  }
  EXPECT_TRUE(warnings.empty());
}

}  // namespace
}  // namespace px
