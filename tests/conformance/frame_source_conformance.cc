#include "tests/conformance/frame_source_conformance.h"

namespace px::conformance {

using std::chrono::milliseconds;

std::string SourceCaseName(const ::testing::TestParamInfo<SourceCase>& info) { return info.param.name; }

void FrameSourceConformance::SetUp() {
  auto made = GetParam().make(dir_.path(), &clock_);
  if (!made.ok() && made.status().code() == StatusCode::kUnavailable) {
    GTEST_SKIP() << GetParam().name << ": " << made.status().message();
  }
  ASSERT_TRUE(made.ok()) << made.status().ToString();
  source_ = std::move(made).value();
}

ConfigureResult FrameSourceConformance::ConfigureNative(SourceConfig* granted) {
  SourceConfig wanted;
  wanted.pixel_format = PixelFormat::kRgb888;
  auto result = source_->Configure(wanted, granted);
  EXPECT_TRUE(result.ok()) << result.status().ToString();
  return result.ok() ? *result : ConfigureResult::kAdjusted;
}

TEST_P(FrameSourceConformance, DescribesItself) {
  EXPECT_FALSE(source_->Name().empty());
  SourceDescription description = source_->Describe();
  EXPECT_FALSE(description.model.empty());
  if (description.rig) {
    EXPECT_TRUE(description.rig->Validate().ok()) << description.rig->Validate().ToString();
  }
}

TEST_P(FrameSourceConformance, NextBeforeConfigureIsAPreconditionError) {
  auto frames = source_->Next(milliseconds(1000));
  ASSERT_FALSE(frames.ok());
  EXPECT_EQ(frames.status().code(), StatusCode::kFailedPrecondition) << frames.status().ToString();
}

TEST_P(FrameSourceConformance, DeliversWhatItGranted) {
  SourceConfig granted;
  ConfigureNative(&granted);
  EXPECT_GT(granted.width, 0);
  EXPECT_GT(granted.height, 0);
  auto frames = source_->Next(milliseconds(10000));
  ASSERT_TRUE(frames.ok()) << frames.status().ToString();
  ASSERT_FALSE(frames->frames.empty());
  FrameSet checked = *frames;
  EXPECT_TRUE(CheckFrameSet(granted, &checked).ok());
  EXPECT_EQ(checked.NumUsableFrames(), static_cast<int>(checked.frames.size()));
  for (const Frame& frame : checked.frames) EXPECT_TRUE(frame.image.Validate().ok());

  // A lattice source's frame must fit its own rig calibration's lattice.
  SourceDescription description = source_->Describe();
  if (description.kind == FrameSetKind::kLatticeFrame && description.rig && description.rig->lattice.rows > 0) {
    EXPECT_EQ(checked.frames[0].image.width, description.rig->lattice.sensor_width);
    EXPECT_EQ(checked.frames[0].image.height, description.rig->lattice.sensor_height);
  }
}

TEST_P(FrameSourceConformance, SequenceAndTimeMoveForward) {
  SourceConfig granted;
  ConfigureNative(&granted);
  auto first = source_->Next(milliseconds(10000));
  auto second = source_->Next(milliseconds(10000));
  ASSERT_TRUE(first.ok()) << first.status().ToString();
  ASSERT_TRUE(second.ok()) << second.status().ToString();
  EXPECT_NE(first->capture_id, second->capture_id);
  EXPECT_GT(second->frames[0].sequence, first->frames[0].sequence);
  EXPECT_GE(second->frames[0].timestamp_ns, first->frames[0].timestamp_ns);
}

TEST_P(FrameSourceConformance, AnUnsupportedSizeIsAdjustedNotObeyed) {
  SourceConfig wanted;
  wanted.pixel_format = PixelFormat::kRgb888;
  wanted.width = 17;
  wanted.height = 13;
  SourceConfig granted;
  auto result = source_->Configure(wanted, &granted);
  if (!result.ok()) {
    EXPECT_EQ(result.status().code(), StatusCode::kInvalidArgument);
    return;
  }
  EXPECT_EQ(*result, ConfigureResult::kAdjusted);
  EXPECT_NE(granted, wanted);
  auto frames = source_->Next(milliseconds(10000));
  ASSERT_TRUE(frames.ok()) << frames.status().ToString();
  FrameSet checked = *frames;
  EXPECT_TRUE(CheckFrameSet(granted, &checked).ok());
}

TEST_P(FrameSourceConformance, StopIsIdempotentAndEndsCapture) {
  SourceConfig granted;
  ConfigureNative(&granted);
  source_->Stop();
  source_->Stop();
  auto frames = source_->Next(milliseconds(1000));
  ASSERT_FALSE(frames.ok());
  EXPECT_EQ(frames.status().code(), StatusCode::kFailedPrecondition);
  // Configuring again brings it back.
  ConfigureNative(&granted);
  EXPECT_TRUE(source_->Next(milliseconds(10000)).ok());
}

}  // namespace px::conformance
