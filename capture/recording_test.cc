// Round trips, durability and the writer's own refusals. Corrupt recordings are in
// recording_corruption_test.cc, random manifest damage in recording_fuzz_test.cc.
#include "capture/recording.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>

#include <cerrno>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "capture/recording_manifest.h"
#include "capture/recording_test_util.h"
#include "capture/sha256.h"
#include "pipeline/io/durable_file.h"

namespace px {
namespace {

namespace fs = std::filesystem;
using capture::testing::ImageSetRecording;
using capture::testing::LatticeRecording;
using capture::testing::ReadText;
using capture::testing::ScratchDir;
using ::testing::HasSubstr;

std::vector<uint8_t> Bytes(const std::string& text) { return {text.begin(), text.end()}; }

TEST(Sha256Test, MatchesFips180Vectors) {
  EXPECT_EQ(capture::Sha256Hex({}), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(capture::Sha256Hex(Bytes("abc")), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  // 56 bytes: the padding needs a second block.
  EXPECT_EQ(capture::Sha256Hex(Bytes("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq")),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(capture::Sha256Hex(std::vector<uint8_t>(1'000'000, 'a')),
            "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

class RoundTripTest : public ::testing::TestWithParam<PixelFormat> {};

TEST_P(RoundTripTest, LatticeFrameComesBackExactly) {
  ScratchDir scratch;
  const fs::path dir = scratch.path() / "shot";
  const Recording recording = LatticeRecording(GetParam(), 3);
  ASSERT_TRUE(WriteRecording(dir, recording).ok());

  const bool png =
      GetParam() == PixelFormat::kRgb888 || GetParam() == PixelFormat::kBgr888 || GetParam() == PixelFormat::kGray8;
  EXPECT_TRUE(fs::exists(dir / (png ? "frame_0000.png" : "frame_0000.raw")));
  EXPECT_TRUE(fs::exists(dir / "manifest.json"));
  // Nothing but the frame and the manifest: no temporary files left over.
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 2);

  StatusOr<Recording> back = ReadRecording(dir);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  capture::testing::ExpectSameRecording(recording, *back);
}

INSTANTIATE_TEST_SUITE_P(EveryPixelFormat,
                         RoundTripTest,
                         ::testing::Values(PixelFormat::kRgb888,
                                           PixelFormat::kBgr888,
                                           PixelFormat::kGray8,
                                           PixelFormat::kYuyv,
                                           PixelFormat::kNv12,
                                           PixelFormat::kBayerRggb8),
                         [](const auto& param_info) { return std::string(PixelFormatName(param_info.param)); });

TEST(RecordingTest, ColourPngShowsTheTrueColoursInOtherTools) {
  for (PixelFormat format : {PixelFormat::kRgb888, PixelFormat::kBgr888}) {
    SCOPED_TRACE(std::string(PixelFormatName(format)));
    ScratchDir scratch;
    const Recording recording = LatticeRecording(format, 4);
    ASSERT_TRUE(WriteRecording(scratch.path() / "shot", recording).ok());
    // A plain PNG reader must see the picture, not its channels swapped.
    const cv::Mat seen = cv::imread((scratch.path() / "shot" / "frame_0000.png").string(), cv::IMREAD_COLOR);
    StatusOr<cv::Mat> want = ToBgr(recording.frames.frames[0].image);
    ASSERT_TRUE(want.ok());
    ASSERT_EQ(seen.size(), want->size());
    EXPECT_EQ(cv::norm(seen, *want, cv::NORM_INF), 0);
  }
}

// A frame decoded from its camera's JPEG is stored as that JPEG, byte for byte (no re-encoding:
// the capture as it came, and an import of a 24 MP photo in well under a second), and reads back
// as the same JPEG and the pixels it decodes to.
TEST(RecordingTest, ACamerasJpegIsKeptAsItCame) {
  ScratchDir scratch;
  Recording recording = LatticeRecording(PixelFormat::kRgb888, 4);
  Frame& frame = recording.frames.frames[0];
  StatusOr<cv::Mat> bgr = ToBgr(frame.image);
  ASSERT_TRUE(bgr.ok());
  ASSERT_TRUE(cv::imencode(".jpg", *bgr, frame.jpeg, {cv::IMWRITE_JPEG_QUALITY, 90}));
  ASSERT_TRUE(WriteRecording(scratch.path() / "shot", recording).ok());
  const fs::path stored = scratch.path() / "shot" / "frame_0000.jpg";
  ASSERT_TRUE(fs::exists(stored));
  const std::string text = ReadText(stored);
  EXPECT_EQ(std::vector<uint8_t>(text.begin(), text.end()), frame.jpeg);

  StatusOr<Recording> read = ReadRecording(scratch.path() / "shot");
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  const Frame& back = read->frames.frames[0];
  EXPECT_EQ(back.jpeg, frame.jpeg);
  EXPECT_EQ(back.image.format, PixelFormat::kRgb888);
  StatusOr<cv::Mat> back_bgr = ToBgr(back.image);
  ASSERT_TRUE(back_bgr.ok());
  EXPECT_EQ(cv::norm(*back_bgr, cv::imdecode(frame.jpeg, cv::IMREAD_COLOR), cv::NORM_INF), 0);
  // Written again from what was read, it is the same file.
  ASSERT_TRUE(WriteRecording(scratch.path() / "again", *read).ok());
  EXPECT_EQ(ReadText(scratch.path() / "again" / "frame_0000.jpg"), text);
}

TEST(RecordingTest, AJpegThatNoLongerHoldsTheImageIsNotStored) {
  // The image was changed (resized) after decoding: its pixels are stored, not the stale JPEG.
  ScratchDir scratch;
  Recording recording = LatticeRecording(PixelFormat::kRgb888, 4);
  Frame& frame = recording.frames.frames[0];
  ASSERT_TRUE(cv::imencode(".jpg", cv::Mat(10, 12, CV_8UC3, cv::Scalar(1, 2, 3)), frame.jpeg));
  ASSERT_TRUE(WriteRecording(scratch.path() / "shot", recording).ok());
  EXPECT_TRUE(fs::exists(scratch.path() / "shot" / "frame_0000.png"));
  EXPECT_FALSE(fs::exists(scratch.path() / "shot" / "frame_0000.jpg"));
}

TEST(RecordingTest, ImageSetWithEveryFrameStatusComesBackExactly) {
  ScratchDir scratch;
  Recording recording = ImageSetRecording(5, PixelFormat::kBgr888);
  // A frame marked corrupt keeps its short buffer byte for byte (stored raw, not as PNG).
  Frame& corrupt = recording.frames.frames[1];
  corrupt.image.bytes.resize(corrupt.image.bytes.size() / 3);
  corrupt.status = FrameStatus::kCorrupt;
  corrupt.status_detail = "short read: 3072 of 9216 bytes";
  // A frame of the wrong format is kept as delivered.
  Frame& wrong = recording.frames.frames[3];
  wrong.image = capture::testing::TestImage(PixelFormat::kNv12, 64, 48, 99);
  wrong.status = FrameStatus::kWrongFormat;
  wrong.status_detail = "got 64x48 NV12, want 64x48 BGR888";
  ASSERT_TRUE(WriteRecording(scratch.path() / "set", recording).ok());
  EXPECT_TRUE(fs::exists(scratch.path() / "set" / "frame_0001.raw"));
  EXPECT_TRUE(fs::exists(scratch.path() / "set" / "frame_0003.raw"));
  EXPECT_TRUE(fs::exists(scratch.path() / "set" / "frame_0004.png"));

  StatusOr<Recording> back = ReadRecording(scratch.path() / "set");
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  capture::testing::ExpectSameRecording(recording, *back);
  EXPECT_EQ(back->frames.NumUsableFrames(), 3);
}

TEST(RecordingTest, DroppedFrameHasNoFileAndKeepsItsStatus) {
  ScratchDir scratch;
  Recording recording = ImageSetRecording(3, PixelFormat::kYuyv);
  Frame& dropped = recording.frames.frames[2];
  dropped.image.bytes.clear();
  dropped.status = FrameStatus::kDropped;
  dropped.status_detail = "no buffer within 500 ms";
  ASSERT_TRUE(WriteRecording(scratch.path() / "set", recording).ok());
  EXPECT_FALSE(fs::exists(scratch.path() / "set" / "frame_0002.raw"));

  const nlohmann::json manifest = nlohmann::json::parse(ReadText(scratch.path() / "set" / "manifest.json"));
  EXPECT_TRUE(manifest["frames"][2]["file"].is_null());
  EXPECT_EQ(manifest["frames"][2]["status"], "dropped");
  EXPECT_EQ(manifest["frames"][2]["bytes"], 0);

  StatusOr<Recording> back = ReadRecording(scratch.path() / "set");
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  capture::testing::ExpectSameRecording(recording, *back);
}

TEST(RecordingTest, ManifestHasTheDocumentedFields) {
  ScratchDir scratch;
  ASSERT_TRUE(WriteRecording(scratch.path() / "shot", LatticeRecording(PixelFormat::kNv12)).ok());
  const nlohmann::json m = nlohmann::json::parse(ReadText(scratch.path() / "shot" / "manifest.json"));
  EXPECT_EQ(m["format"], "parallax.recording");
  EXPECT_EQ(m["format_version"], 1);
  EXPECT_EQ(m["source"]["kind"], "lattice_frame");
  EXPECT_EQ(m["source"]["rig_calibration"]["schema"], "parallax.rig_calibration");
  const nlohmann::json& frame = m["frames"][0];
  EXPECT_EQ(frame["file"], "frame_0000.raw");
  EXPECT_EQ(frame["pixel_format"], "NV12");
  EXPECT_EQ(frame["width"], 136);
  EXPECT_EQ(frame["height"], 106);
  EXPECT_EQ(frame["bytes"], 136 * 106 * 3 / 2);
  EXPECT_EQ(frame["status"], "ok");
  const std::string file = ReadText(scratch.path() / "shot" / "frame_0000.raw");
  EXPECT_EQ(frame["sha256"], capture::Sha256Hex(Bytes(file)));
}

// The example in FORMAT.md must stay a valid manifest.
TEST(RecordingTest, FormatDocumentExampleIsAValidManifest) {
  const std::string doc = ReadText(fs::path(PX_SOURCE_DIR) / "capture" / "FORMAT.md");
  const size_t start = doc.find("```json\n");
  ASSERT_NE(start, std::string::npos);
  const size_t end = doc.find("```", start + 8);
  const nlohmann::json example = nlohmann::json::parse(doc.substr(start + 8, end - start - 8));
  StatusOr<capture::Manifest> manifest = capture::ManifestFromJson(example);
  ASSERT_TRUE(manifest.ok()) << manifest.status().ToString();
  EXPECT_EQ(manifest->source.rig->NumViews(), 2);
  EXPECT_EQ(manifest->frames[0].sequence, 3071u);
}

TEST(RecordingTest, StampsCreationTimeWhenNoneIsGiven) {
  ScratchDir scratch;
  Recording recording = LatticeRecording(PixelFormat::kGray8);
  recording.created_at.clear();
  ASSERT_TRUE(WriteRecording(scratch.path() / "shot", recording).ok());
  StatusOr<Recording> back = ReadRecording(scratch.path() / "shot");
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_TRUE(capture::IsUtcIso8601(back->created_at)) << back->created_at;
  EXPECT_EQ(back->created_at.substr(0, 2), "20");
}

TEST(RecordingTest, InvalidUtf8InFreeTextIsReplacedNotFatal) {
  ScratchDir scratch;
  Recording recording = ImageSetRecording(2, PixelFormat::kGray8);
  recording.frames.frames[1].status = FrameStatus::kCorrupt;
  recording.frames.frames[1].status_detail = "driver said \xff\xfe";
  ASSERT_TRUE(WriteRecording(scratch.path() / "set", recording).ok());
  StatusOr<Recording> back = ReadRecording(scratch.path() / "set");
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(back->frames.frames[1].status_detail, "driver said \xef\xbf\xbd\xef\xbf\xbd");  // U+FFFD twice
}

TEST(RecordingTest, Iso8601CheckAcceptsUtcOnly) {
  EXPECT_TRUE(capture::IsUtcIso8601("2025-03-01T12:34:56Z"));
  EXPECT_TRUE(capture::IsUtcIso8601("2025-03-01T12:34:56.123456Z"));
  EXPECT_FALSE(capture::IsUtcIso8601("2025-03-01T12:34:56+01:00"));
  EXPECT_FALSE(capture::IsUtcIso8601("2025-13-01T12:34:56Z"));
  EXPECT_FALSE(capture::IsUtcIso8601("2025-03-01 12:34:56Z"));
  EXPECT_FALSE(capture::IsUtcIso8601("2025-03-01T12:34:56.Z"));
  EXPECT_FALSE(capture::IsUtcIso8601(""));
}

TEST(RecordingTest, WritesIntoAnEmptyFolderButNotANonEmptyOne) {
  ScratchDir scratch;
  ASSERT_TRUE(WriteRecording(scratch.path(), LatticeRecording(PixelFormat::kBgr888)).ok()) << "empty folder";

  const fs::path busy = scratch.path() / "busy";
  fs::create_directories(busy);
  capture::testing::WriteText(busy / "notes.txt", "keep me");
  Status status = WriteRecording(busy, LatticeRecording(PixelFormat::kBgr888));
  EXPECT_EQ(status.code(), StatusCode::kAlreadyExists) << status.ToString();
  EXPECT_THAT(status.message(), HasSubstr(busy.string()));
  EXPECT_THAT(status.message(), HasSubstr("not empty"));
  EXPECT_EQ(ReadText(busy / "notes.txt"), "keep me");
  EXPECT_FALSE(fs::exists(busy / "manifest.json"));
  EXPECT_FALSE(fs::exists(busy / "frame_0000.png"));

  capture::testing::WriteText(scratch.path() / "a_file", "x");
  status = WriteRecording(scratch.path() / "a_file", LatticeRecording(PixelFormat::kBgr888));
  EXPECT_EQ(status.code(), StatusCode::kAlreadyExists) << status.ToString();
}

TEST(RecordingTest, RefusesARecordingThatContradictsItself) {
  ScratchDir scratch;
  const fs::path dir = scratch.path() / "shot";

  Recording short_ok = LatticeRecording(PixelFormat::kYuyv);
  short_ok.frames.frames[0].image.bytes.pop_back();  // marked ok, but a byte short
  Status status = WriteRecording(dir, short_ok);
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(), HasSubstr("frames[0]: status ok but"));

  Recording mixed = LatticeRecording(PixelFormat::kYuyv);
  mixed.frames.kind = FrameSetKind::kImageSet;
  EXPECT_THAT(WriteRecording(dir, mixed).message(), HasSubstr("differs from source.kind"));

  Recording wrong_sensor = LatticeRecording(PixelFormat::kBgr888);
  wrong_sensor.frames.frames[0].image = capture::testing::TestImage(PixelFormat::kBgr888, 138, 106, 1);
  status = WriteRecording(dir, wrong_sensor);
  EXPECT_THAT(status.message(), HasSubstr("frames[0].width, height: 138x106 differs from the lattice's sensor size"));

  Recording no_frames = LatticeRecording(PixelFormat::kBgr888);
  no_frames.frames.frames.clear();
  EXPECT_THAT(WriteRecording(dir, no_frames).message(), HasSubstr("frames: empty"));

  // Refused before touching the disk.
  EXPECT_FALSE(fs::exists(dir));
}

// A crash at any point of the write must not leave a folder ReadRecording accepts: the hook
// runs exactly where a crash would stop the writer, just before each rename.
TEST(RecordingTest, ManifestIsCommittedLastSoAnInterruptedWriteIsNeverARecording) {
  ScratchDir scratch;
  const fs::path dir = scratch.path() / "set";
  const Recording recording = ImageSetRecording(3, PixelFormat::kRgb888);
  std::vector<std::string> order;
  bool checked_at_manifest = false;
  Status status = WriteRecording(dir, recording, [&](const fs::path& final_path) -> Status {
    order.push_back(final_path.filename().string());
    // At this instant the folder is what a crash would leave.
    StatusOr<Recording> snapshot = ReadRecording(dir);
    EXPECT_FALSE(snapshot.ok()) << "accepted a half-written recording before " << final_path;
    if (final_path.filename() == "manifest.json") {
      checked_at_manifest = true;
      for (const char* frame : {"frame_0000.png", "frame_0001.png", "frame_0002.png"}) {
        EXPECT_TRUE(fs::exists(dir / frame)) << frame << " must be in place before the manifest";
      }
      bool manifest_temporary = false;
      for (const auto& entry : fs::directory_iterator(dir)) {
        const std::string name = entry.path().filename().string();
        manifest_temporary |= IsTemporaryName(name) && name.find("manifest") != std::string::npos;
      }
      EXPECT_TRUE(manifest_temporary) << "manifest written, not yet renamed";
      return UnavailableError("simulated crash before the manifest rename");
    }
    return OkStatus();
  });
  EXPECT_TRUE(checked_at_manifest);
  EXPECT_EQ(order, (std::vector<std::string>{"frame_0000.png", "frame_0001.png", "frame_0002.png", "manifest.json"}));
  EXPECT_EQ(status.code(), StatusCode::kUnavailable);
  // The failed write cleaned up after itself: the folder it created is gone again.
  EXPECT_FALSE(fs::exists(dir));
  EXPECT_EQ(ReadRecording(dir).status().code(), StatusCode::kNotFound);
}

TEST(RecordingTest, FailureHalfWayIntoAnExistingFolderLeavesItEmpty) {
  ScratchDir scratch;
  Status status = WriteRecording(
      scratch.path(), ImageSetRecording(3, PixelFormat::kGray8), [](const fs::path& final_path) -> Status {
        if (final_path.filename() == "frame_0001.png") {
          return ResourceExhaustedError("simulated full disk");
        }
        return OkStatus();
      });
  EXPECT_EQ(status.code(), StatusCode::kResourceExhausted);
  EXPECT_TRUE(fs::exists(scratch.path()));  // not ours to remove
  EXPECT_TRUE(fs::is_empty(scratch.path()));
}

// A real I/O failure in the middle of the write: RLIMIT_FSIZE makes write() fail with EFBIG
// (SIGXFSZ ignored) once a file would pass the limit, as a full disk fails with ENOSPC.
TEST(RecordingTest, RealWriteFailureHalfWayIsResourceExhaustedAndLeavesNothing) {
  ScratchDir scratch;
  const fs::path dir = scratch.path() / "set";
  const Recording recording = ImageSetRecording(3, PixelFormat::kNv12);  // raw: 4608 bytes each
  const rlim_t frame_bytes = recording.frames.frames[0].image.bytes.size();

  rlimit saved{};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &saved), 0);
  struct sigaction ignore {
  }, previous{};
  ignore.sa_handler = SIG_IGN;
  ASSERT_EQ(sigaction(SIGXFSZ, &ignore, &previous), 0);
  rlimit tight = saved;
  tight.rlim_cur = frame_bytes - 100;  // the first frame file already does not fit
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &tight), 0);
  Status status = WriteRecording(dir, recording);
  setrlimit(RLIMIT_FSIZE, &saved);
  sigaction(SIGXFSZ, &previous, nullptr);

  EXPECT_EQ(status.code(), StatusCode::kResourceExhausted) << status.ToString();
  EXPECT_THAT(status.message(), HasSubstr("disk full"));
  EXPECT_THAT(status.message(), HasSubstr("MB free under " + dir.string()));
  EXPECT_THAT(status.message(), HasSubstr((dir / "frame_0000.raw").string()));
  EXPECT_FALSE(fs::exists(dir));
}

}  // namespace
}  // namespace px
