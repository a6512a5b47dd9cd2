#include "pipeline/clip/clip_writer.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "pipeline/clip/clip_test_util.h"
#include "tests/testing/animation_probe.h"
#include "tests/testing/temp_dir.h"
#include "tests/testing/video_probe.h"

namespace px::clip {
namespace {

using ::testing::HasSubstr;

cv::Mat PatternFrame(int width, int height, int index) {
  return testing::PatternFrame(width, height, index, cv::Scalar(230, 60, 240), 3);
}

struct Written {
  std::filesystem::path path;
  std::vector<cv::Mat> frames;
};

class ClipFormatTest : public ::testing::TestWithParam<ClipFormat> {
 protected:
  // Writes `count` pattern frames of width x height in the test's format.
  Written WriteClip(const std::string& name, int width, int height, int count, ClipOptions options) {
    options.format = GetParam();
    Written written;
    written.path = dir_.path() / (name + std::string(ClipFormatExtension(GetParam())));
    StatusOr<std::unique_ptr<ClipWriter>> writer = OpenClipWriter(written.path, width, height, options);
    EXPECT_TRUE(writer.ok()) << writer.status().ToString();
    if (!writer.ok()) return written;
    for (int i = 0; i < count; ++i) {
      written.frames.push_back(PatternFrame(width, height, i));
      const Status status = (*writer)->Write(written.frames.back());
      EXPECT_TRUE(status.ok()) << status.ToString();
    }
    EXPECT_EQ((*writer)->FramesWritten(), count);
    const Status finished = (*writer)->Finish();
    EXPECT_TRUE(finished.ok()) << finished.ToString();
    EXPECT_EQ((*writer)->Finish().code(), StatusCode::kFailedPrecondition);
    EXPECT_EQ((*writer)->Write(written.frames[0]).code(), StatusCode::kFailedPrecondition);
    return written;
  }

  ::px::testing::TempDir dir_;
};

// What each format must give back: frame count and size always; the loop flag where the format
// has one; the frames' content within the format's loss.
TEST_P(ClipFormatTest, DecodesBackWithEveryFrameAtFullSize) {
  ClipOptions options;
  options.fps = 25;
  const Written clip = WriteClip("clip", 96, 64, 12, options);
  switch (GetParam()) {
    case ClipFormat::kMp4: {
      StatusOr<::px::testing::VideoProbe> probe = ::px::testing::ProbeVideo(clip.path);
      ASSERT_TRUE(probe.ok()) << probe.status().ToString();
      EXPECT_EQ(probe->codec, "h264");
      EXPECT_EQ(probe->pixel_format, "yuv420p");
      EXPECT_TRUE(probe->moov_before_mdat);
      EXPECT_EQ(probe->frames_decoded, 12);
      EXPECT_EQ(probe->width, 96);
      EXPECT_EQ(probe->height, 64);
      EXPECT_NEAR(probe->fps, 25.0, 1e-9);
      // CRF 20 on a frame this small, with a saturated disc whose edge chroma subsampling blurs:
      // ~27 dB; neighbouring frames are ~20 dB apart (mp4_writer_test checks quality at size).
      EXPECT_GT(cv::PSNR(probe->last_frame, clip.frames.back()), 25.0);
      EXPECT_LT(cv::PSNR(probe->last_frame, clip.frames.front()), 25.0);
      break;
    }
    case ClipFormat::kGif:
    case ClipFormat::kWebp: {
      StatusOr<::px::testing::AnimationProbe> probe = ::px::testing::ProbeAnimation(clip.path);
      ASSERT_TRUE(probe.ok()) << probe.status().ToString();
      EXPECT_EQ(probe->format, ClipFormatName(GetParam()));
      EXPECT_EQ(probe->frames, 12);
      EXPECT_EQ(probe->width, 96);
      EXPECT_EQ(probe->height, 64);
      EXPECT_EQ(probe->plays, 0) << "loops forever by default";
      EXPECT_NEAR(probe->duration_s, 12 / 25.0, 0.011);  // GIF delays are whole hundredths
      // GIF: 255 colours with dithering on smooth gradients keep ~30 dB; WebP at quality 80 ~35.
      // Either is far above the ~20 dB between neighbouring frames, so frame order is checked too.
      const double floor_db = GetParam() == ClipFormat::kGif ? 27.0 : 30.0;
      EXPECT_GT(cv::PSNR(probe->first_frame, clip.frames.front()), floor_db);
      EXPECT_GT(cv::PSNR(probe->last_frame, clip.frames.back()), floor_db);
      EXPECT_LT(cv::PSNR(probe->last_frame, clip.frames.front()), floor_db);
      break;
    }
    case ClipFormat::kPng: {
      ASSERT_TRUE(std::filesystem::is_directory(clip.path));
      std::vector<std::string> names;
      for (const auto& entry : std::filesystem::directory_iterator(clip.path)) {
        names.push_back(entry.path().filename().string());
      }
      std::sort(names.begin(), names.end());
      ASSERT_EQ(names.size(), 12u);
      EXPECT_EQ(names.front(), "frame_00000.png");
      EXPECT_EQ(names.back(), "frame_00011.png");
      for (size_t i = 0; i < names.size(); ++i) {
        const cv::Mat decoded = cv::imread((clip.path / names[i]).string(), cv::IMREAD_UNCHANGED);
        ASSERT_EQ(decoded.type(), CV_8UC3);
        EXPECT_EQ(cv::norm(decoded, clip.frames[i], cv::NORM_INF), 0.0) << names[i] << " is lossless";
      }
      break;
    }
  }
}

TEST_P(ClipFormatTest, OddSizesAreKeptWhereTheFormatAllows) {
  const Written clip = WriteClip("odd", 101, 75, 3, ClipOptions{});
  int width = 0;
  int height = 0;
  if (GetParam() == ClipFormat::kMp4) {
    StatusOr<::px::testing::VideoProbe> probe = ::px::testing::ProbeVideo(clip.path);
    ASSERT_TRUE(probe.ok()) << probe.status().ToString();
    width = probe->width;
    height = probe->height;
    EXPECT_EQ(width, 100) << "yuv420p H.264 needs even sizes: the last column goes";
    EXPECT_EQ(height, 74);
  } else if (GetParam() == ClipFormat::kPng) {
    const cv::Mat frame = cv::imread((clip.path / "frame_00002.png").string());
    EXPECT_EQ(frame.cols, 101);
    EXPECT_EQ(frame.rows, 75);
  } else {
    StatusOr<::px::testing::AnimationProbe> probe = ::px::testing::ProbeAnimation(clip.path);
    ASSERT_TRUE(probe.ok()) << probe.status().ToString();
    EXPECT_EQ(probe->width, 101);
    EXPECT_EQ(probe->height, 75);
    EXPECT_EQ(probe->frames, 3);
  }
}

TEST_P(ClipFormatTest, FramesOfTheWrongSizeOrNoFramesAreErrors) {
  ClipOptions options;
  options.format = GetParam();
  const std::filesystem::path path = dir_.path() / ("bad" + std::string(ClipFormatExtension(GetParam())));
  StatusOr<std::unique_ptr<ClipWriter>> writer = OpenClipWriter(path, 64, 48, options);
  ASSERT_TRUE(writer.ok()) << writer.status().ToString();
  const Status wrong = (*writer)->Write(cv::Mat(48, 65, CV_8UC3, cv::Scalar::all(0)));
  EXPECT_EQ(wrong.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(wrong.message(), HasSubstr("frame 0 is 65x48"));
  EXPECT_EQ((*writer)->Write(cv::Mat(48, 64, CV_8UC1, cv::Scalar::all(0))).code(), StatusCode::kInvalidArgument);
  EXPECT_EQ((*writer)->Finish().code(), StatusCode::kFailedPrecondition);

  const Status tiny = OpenClipWriter(dir_.path() / "tiny", 0, 48, options).status();
  EXPECT_EQ(tiny.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(tiny.message(), HasSubstr("0x48"));
  const Status nowhere =
      OpenClipWriter(dir_.path() / "no" / ("such" + std::string(ClipFormatExtension(GetParam()))), 64, 48, options)
          .status();
  EXPECT_FALSE(nowhere.ok());
  EXPECT_THAT(nowhere.message(), HasSubstr("no/such"));
}

INSTANTIATE_TEST_SUITE_P(Formats,
                         ClipFormatTest,
                         ::testing::Values(ClipFormat::kMp4, ClipFormat::kGif, ClipFormat::kWebp, ClipFormat::kPng),
                         [](const auto& param_info) { return std::string(ClipFormatName(param_info.param)); });

class LoopingFormatTest : public ClipFormatTest {};

TEST_P(LoopingFormatTest, LoopCountIsStored) {
  for (int plays : {1, 3}) {
    ClipOptions options;
    options.loop_count = plays;
    const Written clip = WriteClip("loop" + std::to_string(plays), 32, 24, 2, options);
    StatusOr<::px::testing::AnimationProbe> probe = ::px::testing::ProbeAnimation(clip.path);
    ASSERT_TRUE(probe.ok()) << probe.status().ToString();
    EXPECT_EQ(probe->plays, plays);
  }
}

INSTANTIATE_TEST_SUITE_P(Formats,
                         LoopingFormatTest,
                         ::testing::Values(ClipFormat::kGif, ClipFormat::kWebp),
                         [](const auto& param_info) { return std::string(ClipFormatName(param_info.param)); });

TEST(ClipWriterTest, LosslessWebpKeepsEveryPixel) {
  ::px::testing::TempDir dir;
  ClipOptions options;
  options.format = ClipFormat::kWebp;
  options.webp_lossless = true;
  const cv::Mat frame = PatternFrame(40, 30, 0);
  auto writer = OpenClipWriter(dir.path() / "lossless.webp", 40, 30, options);
  ASSERT_TRUE(writer.ok()) << writer.status().ToString();
  ASSERT_TRUE((*writer)->Write(frame).ok());
  ASSERT_TRUE((*writer)->Write(PatternFrame(40, 30, 1)).ok());
  ASSERT_TRUE((*writer)->Finish().ok());
  StatusOr<::px::testing::AnimationProbe> probe = ::px::testing::ProbeAnimation(dir.path() / "lossless.webp");
  ASSERT_TRUE(probe.ok()) << probe.status().ToString();
  EXPECT_EQ(cv::norm(probe->first_frame, frame, cv::NORM_INF), 0.0);
}

// The clip is as large as its frames: nothing caps the size below what the format can store.
TEST(ClipWriterTest, LargeFramesAreNotScaledDown) {
  ::px::testing::TempDir dir;
  const cv::Mat frame = PatternFrame(2400, 1600, 0);
  for (ClipFormat format : {ClipFormat::kGif, ClipFormat::kWebp}) {
    ClipOptions options;
    options.format = format;
    const std::filesystem::path path = dir.path() / ("large" + std::string(ClipFormatExtension(format)));
    auto writer = OpenClipWriter(path, 2400, 1600, options);
    ASSERT_TRUE(writer.ok()) << writer.status().ToString();
    ASSERT_TRUE((*writer)->Write(frame).ok());
    ASSERT_TRUE((*writer)->Finish().ok());
    StatusOr<::px::testing::AnimationProbe> probe = ::px::testing::ProbeAnimation(path);
    ASSERT_TRUE(probe.ok()) << probe.status().ToString();
    EXPECT_EQ(probe->width, 2400) << ClipFormatName(format);
    EXPECT_EQ(probe->height, 1600) << ClipFormatName(format);
  }
}

TEST(ClipWriterTest, APngFolderThatHoldsFilesIsNotOverwritten) {
  ::px::testing::TempDir dir;
  std::filesystem::create_directories(dir.path() / "frames");
  cv::imwrite((dir.path() / "frames" / "mine.png").string(), PatternFrame(8, 8, 0));
  ClipOptions options;
  options.format = ClipFormat::kPng;
  const Status status = OpenClipWriter(dir.path() / "frames", 8, 8, options).status();
  EXPECT_EQ(status.code(), StatusCode::kAlreadyExists);
  EXPECT_THAT(status.message(), HasSubstr("frames"));
}

TEST(ClipWriterTest, OptionsAndNamesAreChecked) {
  EXPECT_EQ(*ParseClipFormat("gif"), ClipFormat::kGif);
  EXPECT_EQ(*ParseClipFormat("png"), ClipFormat::kPng);
  EXPECT_THAT(ParseClipFormat("avi").status().message(), HasSubstr("clip.format: \"avi\""));
  EXPECT_EQ(ClipFormatExtension(ClipFormat::kWebp), ".webp");
  EXPECT_EQ(ClipFormatExtension(ClipFormat::kPng), "");
  ClipOptions options;
  options.webp_quality = 101;
  EXPECT_THAT(options.Validate().message(), HasSubstr("clip.webp_quality: 101"));
  options = {};
  options.loop_count = -1;
  EXPECT_THAT(options.Validate().message(), HasSubstr("clip.loop_count: -1"));
  options = {};
  options.png_compression = 10;
  EXPECT_THAT(options.Validate().message(), HasSubstr("clip.png_compression: 10"));
  options = {};
  options.crf = 52;
  EXPECT_THAT(options.Validate().message(), HasSubstr("clip.crf: 52"));
  options = {};
  options.fps = 0;
  EXPECT_THAT(OpenClipWriter("/tmp/x.gif", 8, 8, options).status().message(), HasSubstr("clip.fps"));
}

}  // namespace
}  // namespace px::clip
