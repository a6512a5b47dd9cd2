#include "sim/replay/replay_source.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <spdlog/sinks/base_sink.h>

#include <algorithm>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "capture/recording_test_util.h"
#include "pipeline/core/log.h"
#include "pipeline/core/rig_calibration_json.h"

namespace px {
namespace {

namespace fs = std::filesystem;
using capture::testing::ImageSetRecording;
using capture::testing::LatticeRecording;
using capture::testing::ScratchDir;
using std::chrono::milliseconds;
using ::testing::AllOf;
using ::testing::HasSubstr;

constexpr milliseconds kTimeout(1000);

// Collects what the "replay" logger says while it is alive.
class CapturedLog {
 public:
  CapturedLog() : sink_(std::make_shared<Sink>()) { Logger("replay")->sinks().push_back(sink_); }
  ~CapturedLog() {
    auto& sinks = Logger("replay")->sinks();
    sinks.erase(std::remove(sinks.begin(), sinks.end(), sink_), sinks.end());
  }
  std::string Text() const { return sink_->text; }

 private:
  struct Sink : spdlog::sinks::base_sink<std::mutex> {
    std::string text;
    void sink_it_(const spdlog::details::log_msg& msg) override {
      text += std::string(msg.payload.data(), msg.payload.size()) + "\n";
    }
    void flush_() override {}
  };
  std::shared_ptr<Sink> sink_;
};

// Recordings shot_0.. of LatticeRecording(format) with capture ids 100, 101, ...
void WriteShots(const fs::path& root, int count, PixelFormat format) {
  for (int i = 0; i < count; ++i) {
    Recording recording = LatticeRecording(format, 10 + i);
    recording.frames.capture_id = 100 + i;
    ASSERT_TRUE(WriteRecording(root / ("shot_" + std::to_string(i)), recording).ok());
  }
}

std::unique_ptr<FrameSource> Open(const fs::path& path, const ReplayOptions& options = {}) {
  StatusOr<std::unique_ptr<FrameSource>> source = OpenReplaySource(path, options);
  EXPECT_TRUE(source.ok()) << source.status().ToString();
  return source.ok() ? std::move(source).value() : nullptr;
}

TEST(ReplaySourceTest, DescribesTheRecordedSource) {
  ScratchDir scratch;
  const Recording recording = LatticeRecording(PixelFormat::kNv12);
  ASSERT_TRUE(WriteRecording(scratch.path() / "shot", recording).ok());
  auto source = Open(scratch.path() / "shot");
  ASSERT_NE(source, nullptr);
  EXPECT_EQ(source->Name(), "replay");
  const SourceDescription description = source->Describe();
  EXPECT_EQ(description.model, "replay:" + (scratch.path() / "shot").string());
  EXPECT_EQ(description.kind, FrameSetKind::kLatticeFrame);
  ASSERT_TRUE(description.rig.has_value());
  EXPECT_EQ(RigCalibrationToJson(*description.rig).dump(), RigCalibrationToJson(*recording.source.rig).dump());
}

TEST(ReplaySourceTest, GrantsTheRecordedFormatAndReplaysExactly) {
  ScratchDir scratch;
  const Recording recording = LatticeRecording(PixelFormat::kBayerRggb8);
  ASSERT_TRUE(WriteRecording(scratch.path() / "shot", recording).ok());
  auto source = Open(scratch.path() / "shot");
  ASSERT_NE(source, nullptr);

  SourceConfig granted;
  StatusOr<ConfigureResult> result = source->Configure({PixelFormat::kBayerRggb8, 0, 0, 1}, &granted);
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  EXPECT_EQ(*result, ConfigureResult::kValid);
  EXPECT_EQ(granted, (SourceConfig{PixelFormat::kBayerRggb8, 136, 106, 1}));
  EXPECT_EQ(*source->Configure({PixelFormat::kBayerRggb8, 136, 106, 1}, &granted), ConfigureResult::kValid);

  for (int pass = 0; pass < 2; ++pass) {  // loops by default: the same shot again
    StatusOr<FrameSet> frames = source->Next(kTimeout);
    ASSERT_TRUE(frames.ok()) << frames.status().ToString();
    Recording replayed = recording;
    replayed.frames = *frames;
    capture::testing::ExpectSameRecording(recording, replayed);
  }
}

TEST(ReplaySourceTest, AdjustsInsteadOfConverting) {
  ScratchDir scratch;
  ASSERT_TRUE(WriteRecording(scratch.path() / "shot", LatticeRecording(PixelFormat::kYuyv)).ok());
  auto source = Open(scratch.path() / "shot");
  ASSERT_NE(source, nullptr);
  const SourceConfig recorded{PixelFormat::kYuyv, 136, 106, 1};
  for (const SourceConfig& wanted : {SourceConfig{PixelFormat::kBgr888, 0, 0, 1},
                                     SourceConfig{PixelFormat::kYuyv, 640, 480, 1},
                                     SourceConfig{PixelFormat::kYuyv, 0, 0, 4}}) {
    SourceConfig granted;
    StatusOr<ConfigureResult> result = source->Configure(wanted, &granted);
    ASSERT_TRUE(result.ok());
    EXPECT_EQ(*result, ConfigureResult::kAdjusted) << DescribeConfig(wanted);
    EXPECT_EQ(granted, recorded);
    StatusOr<FrameSet> frames = source->Next(kTimeout);
    ASSERT_TRUE(frames.ok());
    EXPECT_EQ(frames->frames[0].image.format, PixelFormat::kYuyv);  // as recorded, not converted
    EXPECT_EQ(frames->NumUsableFrames(), 1);
  }
}

TEST(ReplaySourceTest, ImageSetGrantsOneShotPerRecordedFrame) {
  ScratchDir scratch;
  ASSERT_TRUE(WriteRecording(scratch.path() / "set", ImageSetRecording(4, PixelFormat::kRgb888)).ok());
  auto source = Open(scratch.path() / "set");
  ASSERT_NE(source, nullptr);
  EXPECT_EQ(source->Describe().kind, FrameSetKind::kImageSet);
  SourceConfig granted;
  EXPECT_EQ(*source->Configure({PixelFormat::kRgb888, 64, 48, 4}, &granted), ConfigureResult::kValid);
  StatusOr<FrameSet> frames = source->Next(kTimeout);
  ASSERT_TRUE(frames.ok());
  EXPECT_EQ(frames->kind, FrameSetKind::kImageSet);
  EXPECT_EQ(frames->frames.size(), 4u);
  EXPECT_EQ(frames->frames[3].sequence, 13u);
}

TEST(ReplaySourceTest, FolderPlaysInNameOrderThenEndsOrLoops) {
  ScratchDir scratch;
  WriteShots(scratch.path(), 3, PixelFormat::kBgr888);
  for (bool loop : {false, true}) {
    ReplayOptions options;
    options.loop = loop;
    auto source = Open(scratch.path(), options);
    ASSERT_NE(source, nullptr);
    EXPECT_EQ(source->Describe().model, "replay:" + scratch.path().string());
    SourceConfig granted;
    ASSERT_TRUE(source->Configure({PixelFormat::kBgr888}, &granted).ok());
    std::vector<uint64_t> ids;
    for (int i = 0; i < 3; ++i) {
      StatusOr<FrameSet> frames = source->Next(kTimeout);
      ASSERT_TRUE(frames.ok()) << frames.status().ToString();
      ids.push_back(frames->capture_id);
      EXPECT_EQ(frames->frames[0].sequence, 1010u + i);  // as recorded
    }
    EXPECT_EQ(ids, (std::vector<uint64_t>{100, 101, 102}));
    StatusOr<FrameSet> after = source->Next(kTimeout);
    if (loop) {
      ASSERT_TRUE(after.ok());
      EXPECT_EQ(after->capture_id, 100u);
    } else {
      EXPECT_EQ(after.status().code(), StatusCode::kOutOfRange);
      EXPECT_THAT(after.status().message(), HasSubstr("all 3 recording(s) played"));
    }
  }
}

TEST(ReplaySourceTest, NextNeedsConfigureAndStopEndsItUntilTheNextConfigure) {
  ScratchDir scratch;
  WriteShots(scratch.path(), 2, PixelFormat::kGray8);
  auto source = Open(scratch.path());
  ASSERT_NE(source, nullptr);
  EXPECT_EQ(source->Next(kTimeout).status().code(), StatusCode::kFailedPrecondition);
  SourceConfig granted;
  ASSERT_TRUE(source->Configure({PixelFormat::kGray8}, &granted).ok());
  ASSERT_EQ(source->Next(kTimeout)->capture_id, 100u);
  ASSERT_EQ(source->Next(kTimeout)->capture_id, 101u);
  source->Stop();
  source->Stop();
  EXPECT_EQ(source->Next(kTimeout).status().code(), StatusCode::kFailedPrecondition);
  ASSERT_TRUE(source->Configure({PixelFormat::kGray8}, &granted).ok());
  EXPECT_EQ(source->Next(kTimeout)->capture_id, 100u);  // Configure rewinds
  EXPECT_EQ(source->Configure({PixelFormat::kGray8}, nullptr).status().code(), StatusCode::kInvalidArgument);
}

TEST(ReplaySourceTest, SkipsUnreadableRecordingsWithAWarning) {
  ScratchDir scratch;
  WriteShots(scratch.path(), 3, PixelFormat::kBgr888);
  fs::remove(scratch.path() / "shot_1" / "frame_0000.png");
  fs::create_directories(scratch.path() / "notes");  // not a recording at all
  CapturedLog log;
  auto source = Open(scratch.path());
  ASSERT_NE(source, nullptr);
  EXPECT_THAT(log.Text(),
              AllOf(HasSubstr("skipping " + (scratch.path() / "shot_1").string()),
                    HasSubstr((scratch.path() / "shot_1" / "frame_0000.png").string() + ": missing"),
                    HasSubstr("skipping " + (scratch.path() / "notes").string()),
                    HasSubstr("manifest.json: missing")));
  SourceConfig granted;
  ASSERT_TRUE(source->Configure({PixelFormat::kBgr888}, &granted).ok());
  EXPECT_EQ(source->Next(kTimeout)->capture_id, 100u);
  EXPECT_EQ(source->Next(kTimeout)->capture_id, 102u);
}

TEST(ReplaySourceTest, FailsWhenNothingIsReadable) {
  ScratchDir scratch;
  StatusOr<std::unique_ptr<FrameSource>> none = OpenReplaySource(scratch.path());
  EXPECT_EQ(none.status().code(), StatusCode::kNotFound);
  EXPECT_THAT(none.status().message(), HasSubstr("no recordings here"));

  EXPECT_EQ(OpenReplaySource(scratch.path() / "absent").status().code(), StatusCode::kNotFound);

  WriteShots(scratch.path(), 2, PixelFormat::kBgr888);
  fs::remove(scratch.path() / "shot_0" / "manifest.json");
  capture::testing::WriteText(scratch.path() / "shot_1" / "manifest.json", "{");
  StatusOr<std::unique_ptr<FrameSource>> broken = OpenReplaySource(scratch.path());
  EXPECT_EQ(broken.status().code(), StatusCode::kNotFound);
  EXPECT_THAT(broken.status().message(),
              AllOf(HasSubstr("none of 2 recording folder(s) is readable"),
                    HasSubstr((scratch.path() / "shot_0" / "manifest.json").string() + ": missing")));

  // One recording named directly: its own error, unchanged.
  StatusOr<std::unique_ptr<FrameSource>> single = OpenReplaySource(scratch.path() / "shot_1");
  EXPECT_THAT(single.status().message(), HasSubstr("malformed JSON"));
}

TEST(ReplaySourceTest, RecordingThatDiffersFromTheGrantedFormatComesBackMarked) {
  ScratchDir scratch;
  ASSERT_TRUE(WriteRecording(scratch.path() / "a", LatticeRecording(PixelFormat::kBgr888)).ok());
  Recording other = ImageSetRecording(2, PixelFormat::kBgr888);  // 64x48, not the 136x106 granted
  ASSERT_TRUE(WriteRecording(scratch.path() / "b", other).ok());
  CapturedLog log;
  auto source = Open(scratch.path());
  ASSERT_NE(source, nullptr);
  EXPECT_THAT(log.Text(), HasSubstr("its frames will be marked"));
  SourceConfig granted;
  ASSERT_TRUE(source->Configure({PixelFormat::kBgr888}, &granted).ok());
  EXPECT_EQ(source->Next(kTimeout)->NumUsableFrames(), 1);
  StatusOr<FrameSet> second = source->Next(kTimeout);
  ASSERT_TRUE(second.ok());
  ASSERT_EQ(second->frames.size(), 2u);
  EXPECT_EQ(second->frames[0].status, FrameStatus::kWrongFormat);
  EXPECT_THAT(second->frames[0].status_detail, HasSubstr("got 64x48 BGR888, want 136x106 BGR888"));
  EXPECT_FALSE(second->frames[0].image.bytes.empty());  // the data is still there
}

TEST(ReplaySourceTest, UncachedRecordingsAreReadOnEachNextAndAVanishedOneIsUnavailable) {
  ScratchDir scratch;
  WriteShots(scratch.path(), 2, PixelFormat::kNv12);
  ReplayOptions options;
  options.max_cached_bytes = 0;
  auto source = Open(scratch.path(), options);
  ASSERT_NE(source, nullptr);
  SourceConfig granted;
  ASSERT_TRUE(source->Configure({PixelFormat::kNv12}, &granted).ok());
  EXPECT_EQ(source->Next(kTimeout)->capture_id, 100u);
  fs::remove_all(scratch.path() / "shot_1");
  StatusOr<FrameSet> vanished = source->Next(kTimeout);
  EXPECT_EQ(vanished.status().code(), StatusCode::kUnavailable);
  EXPECT_THAT(vanished.status().message(), HasSubstr((scratch.path() / "shot_1").string()));
  EXPECT_EQ(source->Next(kTimeout)->capture_id, 100u);  // moves on, and loops
}

}  // namespace
}  // namespace px
