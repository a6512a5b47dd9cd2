// Files that hold several views (capture/import_images.h): a 3D camera's MPO file (mpo.h) and a
// wigglegram's animated GIF or WebP (animation_frames.h, written by the clip writers), made here
// with known views and read from the real files in ../shared/data (skipped without it); damaged
// ones fail naming the file.
#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "capture/animation_frames.h"
#include "capture/import_images.h"
#include "capture/mpo.h"
#include "capture/recording_test_util.h"
#include "pipeline/clip/clip_writer.h"
#include "pipeline/run/image_set_scale.h"
#include "sim/synthetic/data_paths.h"

namespace px {
namespace {

namespace fs = std::filesystem;
using capture::testing::GradientNoiseBgr;
using capture::testing::Jpeg;
using capture::testing::MakeMpo;
using capture::testing::ScratchDir;
using capture::testing::WriteBytes;

TEST(MpoTest, EveryImageOfTheIndexIsAView) {
  const cv::Mat left = GradientNoiseBgr(96, 64, 1), right = GradientNoiseBgr(96, 64, 2);
  const std::vector<uint8_t> mpo = MakeMpo({Jpeg(left), Jpeg(right)});
  StatusOr<std::vector<std::vector<uint8_t>>> images = SplitMpo(mpo, "pair.mpo");
  ASSERT_TRUE(images.ok()) << images.status().ToString();
  ASSERT_EQ(images->size(), 2u);
  EXPECT_LT(cv::norm(cv::imdecode((*images)[1], cv::IMREAD_COLOR), right, cv::NORM_INF), 40);

  ScratchDir dir;
  std::vector<std::string> warnings;
  StatusOr<Recording> recording = RecordingFromImages({WriteBytes(dir.path() / "pair.mpo", mpo)}, &warnings);
  ASSERT_TRUE(recording.ok()) << recording.status().ToString();
  ASSERT_EQ(recording->frames.frames.size(), 2u);
  EXPECT_EQ(recording->frames.frames[1].sequence, 1u);
  EXPECT_EQ(recording->frames.frames[1].image.width, 96);
}

TEST(MpoTest, ABrokenIndexIsNamed) {
  const std::vector<uint8_t> mpo = MakeMpo({Jpeg(GradientNoiseBgr(96, 64, 1)), Jpeg(GradientNoiseBgr(96, 64, 2))});
  // Cut off inside the second image: its entry points past the end.
  const std::vector<uint8_t> truncated(mpo.begin(), mpo.end() - 200);
  StatusOr<std::vector<std::vector<uint8_t>>> images = SplitMpo(truncated, "cut.mpo");
  ASSERT_FALSE(images.ok());
  EXPECT_EQ(images.status().code(), StatusCode::kDataLoss);
  EXPECT_NE(images.status().message().find("cut.mpo: image 1"), std::string::npos) << images.status().message();
  // A plain JPEG has no index.
  EXPECT_NE(SplitMpo(Jpeg(GradientNoiseBgr(32, 32, 3)), "plain.mpo").status().message().find("no MP index"),
            std::string::npos);
  EXPECT_NE(SplitMpo({1, 2, 3, 4}, "junk.mpo").status().message().find("not a JPEG"), std::string::npos);
  // Through the importer: an error naming the file, nothing imported.
  ScratchDir dir;
  std::vector<std::string> warnings;
  StatusOr<Recording> recording = RecordingFromImages({WriteBytes(dir.path() / "cut.mpo", truncated)}, &warnings);
  ASSERT_FALSE(recording.ok());
  EXPECT_NE(recording.status().message().find("cut.mpo"), std::string::npos);
}

// Four views played back and forth (0 1 2 3 2 1), as wigglegram animations are.
std::vector<cv::Mat> PingPong() {
  std::vector<cv::Mat> views;
  for (int i = 0; i < 4; ++i) views.push_back(GradientNoiseBgr(120, 80, 10 + i));
  return {views[0], views[1], views[2], views[3], views[2], views[1]};
}

fs::path WriteAnimation(const fs::path& path, clip::ClipFormat format, const std::vector<cv::Mat>& frames) {
  clip::ClipOptions options;
  options.format = format;
  options.fps = 8;
  options.webp_lossless = true;
  auto writer = clip::OpenClipWriter(path, frames[0].cols, frames[0].rows, options);
  EXPECT_TRUE(writer.ok()) << writer.status().ToString();
  for (const cv::Mat& frame : frames) EXPECT_TRUE((*writer)->Write(frame).ok());
  EXPECT_TRUE((*writer)->Finish().ok());
  return path;
}

TEST(AnimationFramesTest, EachViewOnceInPlayingOrder) {
  ScratchDir dir;
  for (clip::ClipFormat format : {clip::ClipFormat::kGif, clip::ClipFormat::kWebp}) {
    const fs::path file =
        WriteAnimation(dir.path() / ("wiggle" + std::string(clip::ClipFormatExtension(format))), format, PingPong());
    StatusOr<std::vector<cv::Mat>> frames = ReadAnimationFrames(file);
    ASSERT_TRUE(frames.ok()) << frames.status().ToString();
    ASSERT_EQ(frames->size(), 6u) << file;
    const std::vector<cv::Mat> views = WithoutRepeatedFrames(*frames);
    ASSERT_EQ(views.size(), 4u) << file;
    // The views in order, as drawn (the GIF's palette costs a few levels).
    const std::vector<cv::Mat> truth = PingPong();
    for (int i = 0; i < 4; ++i) {
      cv::Mat difference;
      cv::absdiff(views[i], truth[i], difference);
      EXPECT_LT(cv::mean(difference)[0], 8.0) << file << " view " << i;
    }
    std::vector<std::string> warnings;
    StatusOr<Recording> recording = RecordingFromImages({file}, &warnings);
    ASSERT_TRUE(recording.ok()) << recording.status().ToString();
    EXPECT_EQ(recording->frames.frames.size(), 4u);
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_NE(warnings[0].find("2 of its 6 frames repeat"), std::string::npos) << warnings[0];
  }
}

TEST(AnimationFramesTest, OneFrameDamagedChunksAndOtherFilesAreNamed) {
  ScratchDir dir;
  std::vector<std::string> warnings;
  const fs::path single = WriteAnimation(dir.path() / "one.gif", clip::ClipFormat::kGif, {GradientNoiseBgr(64, 48, 1)});
  StatusOr<Recording> recording = RecordingFromImages({single}, &warnings);
  ASSERT_FALSE(recording.ok());
  EXPECT_NE(recording.status().message().find("one.gif: holds 1 view"), std::string::npos)
      << recording.status().message();

  // A WebP whose frame chunks stop short of their stated sizes (a copy broken off).
  const fs::path webp = WriteAnimation(dir.path() / "good.webp", clip::ClipFormat::kWebp, PingPong());
  std::ifstream in(webp, std::ios::binary);
  std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  bytes.resize(bytes.size() * 3 / 5);
  const fs::path garbled = WriteBytes(dir.path() / "garbled.webp", bytes);
  StatusOr<std::vector<cv::Mat>> frames = ReadAnimationFrames(garbled);
  ASSERT_FALSE(frames.ok());
  EXPECT_EQ(frames.status().code(), StatusCode::kDataLoss);
  EXPECT_NE(frames.status().message().find("garbled.webp"), std::string::npos);

  const fs::path text = WriteBytes(dir.path() / "notes.gif", {'h', 'e', 'l', 'l', 'o'});
  EXPECT_NE(ReadAnimationFrames(text).status().message().find("neither a GIF nor a WebP"), std::string::npos);
}

// A folder is one capture. Two files that each hold several views are captures of their own: the
// first by name is taken alone and the rest named. Still GIFs and WebPs are photos, as JPEGs are.
TEST(AnimationFramesTest, AFolderOfSeveralFilesOfViewsIsTakenAsItsFirst) {
  ScratchDir dir;
  const fs::path folder = dir.path() / "shots";
  fs::create_directories(folder);
  const std::vector<cv::Mat> three = {
      GradientNoiseBgr(64, 48, 1), GradientNoiseBgr(64, 48, 2), GradientNoiseBgr(64, 48, 3)};
  const std::vector<fs::path> files = {WriteAnimation(folder / "a.gif", clip::ClipFormat::kGif, three),
                                       WriteAnimation(folder / "b.webp", clip::ClipFormat::kWebp, three),
                                       WriteAnimation(folder / "c.gif", clip::ClipFormat::kGif, {three[0]})};
  std::vector<std::string> warnings;
  StatusOr<Recording> recording = RecordingFromFolder(folder, files, &warnings);
  ASSERT_TRUE(recording.ok()) << recording.status().ToString();
  ASSERT_EQ(recording->frames.frames.size(), 3u);
  for (size_t i = 0; i < 3; ++i) EXPECT_EQ(recording->frames.frames[i].sequence, i);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("the first by name, a.gif, is taken, and b.webp (3 views), c.gif (a photo) left out"),
            std::string::npos)
      << warnings[0];

  // Still GIFs and WebPs: one photo each, an image set of them.
  const fs::path stills = dir.path() / "stills";
  fs::create_directories(stills);
  const std::vector<fs::path> photos = {WriteAnimation(stills / "a.webp", clip::ClipFormat::kWebp, {three[0]}),
                                        WriteAnimation(stills / "b.webp", clip::ClipFormat::kWebp, {three[1]}),
                                        WriteAnimation(stills / "c.gif", clip::ClipFormat::kGif, {three[2]})};
  warnings.clear();
  recording = RecordingFromFolder(stills, photos, &warnings);
  ASSERT_TRUE(recording.ok()) << recording.status().ToString();
  EXPECT_EQ(recording->frames.frames.size(), 3u);
  EXPECT_TRUE(warnings.empty());
}

TEST(MultiViewFilesTest, RealStereoCamerasAndWigglegrams) {
  const fs::path data = sim::SharedDataDir();
  if (!fs::exists(data / "mpo")) GTEST_SKIP() << (data / "mpo").string() << " is absent (the shared real data)";
  struct Case {
    const char* file;
    size_t views;
    int width;
    bool focal;
    bool dithered;  // palette frames whose dither the working image set removes
  };
  const Case cases[] = {
      {"mpo/nintendo3ds_mpo/sugarshack.mpo", 2, 640, false, false},
      {"mpo/nintendo3ds_mpo/3DS-big-endian.mpo", 2, 640, false, false},
      {"mpo/panasonic_gx8_3dlens_mpo/Panasonic-DMC-GX8.mpo", 2, 1824, true, false},
      {"multicam/actionsampler_onomichi_4frames/onomichi.gif", 4, 711, false, true},
      {"multicam/photobooth_pi_4cam_person/wigglegram-example-charuco-calibrated.webp", 4, 1200, false, false}};
  for (const Case& c : cases) {
    std::vector<std::string> warnings;
    StatusOr<Recording> recording = RecordingFromImages({data / c.file}, &warnings);
    ASSERT_TRUE(recording.ok()) << recording.status().ToString();
    ASSERT_EQ(recording->frames.frames.size(), c.views) << c.file;
    EXPECT_EQ(recording->frames.frames[0].image.width, c.width) << c.file;
    // The 3D lens's EXIF: 65 mm equivalent (each image is half the sensor), about 3500 px.
    if (c.focal) {
      EXPECT_NEAR(recording->frames.frames[1].focal_length_px, 3500, 150) << c.file;
    }
    // The recording keeps the frames as decoded; the stages see them without a GIF's dither.
    const std::optional<WorkingImageSet> working = ImageSetAtWorkingSize(0, recording->frames, RigCalibration{});
    EXPECT_EQ(working.has_value(), c.dithered) << c.file << ": " << (working ? working->note : "");
    if (working) {
      EXPECT_NE(working->note.find(std::to_string(c.views) + " of " + std::to_string(c.views) + " frames are palette"),
                std::string::npos)
          << working->note;
    }
  }
}

}  // namespace
}  // namespace px
