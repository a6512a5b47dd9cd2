// One suite over every FrameSource that can run here: each must honour the interface's
// contract (drivers/source/frame_source.h) in the same way. Real drivers join this list with
// GTEST_SKIP() when their hardware is absent.
#include <filesystem>
#include <functional>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "drivers/source/clock.h"
#include "drivers/source/frame_source.h"
#include "sim/replay/recording.h"
#include "sim/replay/replay_source.h"
#include "sim/synthetic/synthetic_source.h"
#include "tests/testing/temp_dir.h"

namespace px {
namespace {

using std::chrono::milliseconds;

// Small cameras keep the suite fast; the geometry is the same as the full-size presets.
SimCameraSpec SmallPop9() {
  SimCameraSpec spec = SimCameraSpec::Pop9();
  spec.tile_width = 160;
  spec.tile_height = 120;
  spec.focal_px = 140;
  spec.gap_px = 6;
  spec.supersampling = 1;
  return spec;
}

SimCameraSpec SmallIntegral() {
  SimCameraSpec spec = SimCameraSpec::Integral5x4();
  spec.tile_width = 96;
  spec.tile_height = 72;
  spec.focal_px = 84;
  spec.gap_px = 4;
  spec.supersampling = 1;
  return spec;
}

std::filesystem::path Scene(const std::string& name) {
  return std::filesystem::path(PX_SOURCE_DIR) / "sim" / "scenes" / (name + ".json");
}

struct SourceCase {
  std::string name;
  // Builds the source; `dir` is a per-test temporary folder it may use.
  std::function<StatusOr<std::unique_ptr<FrameSource>>(const std::filesystem::path& dir, Clock* clock)> make;
};

StatusOr<std::unique_ptr<FrameSource>> MakeSim(const SimCameraSpec& spec, PixelFormat format, Clock* clock) {
  SyntheticSourceOptions options;
  options.camera = spec;
  options.camera.pixel_format = format;
  options.scene_file = Scene("still_life");
  options.clock = clock;
  return MakeSyntheticSource(options);
}

// A replay source over two recordings captured from the simulated camera.
StatusOr<std::unique_ptr<FrameSource>> MakeReplay(const std::filesystem::path& dir, Clock* clock) {
  PX_ASSIGN_OR_RETURN(auto sim, MakeSim(SmallPop9(), PixelFormat::kRgb888, clock));
  SourceConfig granted;
  PX_ASSIGN_OR_RETURN(ConfigureResult configured, sim->Configure(SourceConfig{PixelFormat::kRgb888}, &granted));
  (void)configured;
  for (int i = 0; i < 2; ++i) {
    PX_ASSIGN_OR_RETURN(FrameSet frames, sim->Next(milliseconds(10000)));
    Recording recording;
    recording.source = sim->Describe();
    recording.frames = std::move(frames);
    recording.created_by = "conformance test";
    PX_RETURN_IF_ERROR(WriteRecording(dir / ("shot_" + std::to_string(i)), recording));
  }
  return OpenReplaySource(dir);
}

std::vector<SourceCase> AllSources() {
  return {
      {"sim_pop9_rgb", [](const auto&, Clock* c) { return MakeSim(SmallPop9(), PixelFormat::kRgb888, c); }},
      {"sim_pop9_nv12", [](const auto&, Clock* c) { return MakeSim(SmallPop9(), PixelFormat::kNv12, c); }},
      {"sim_integral_bayer",
       [](const auto&, Clock* c) { return MakeSim(SmallIntegral(), PixelFormat::kBayerRggb8, c); }},
      {"replay", [](const auto& dir, Clock* c) { return MakeReplay(dir, c); }},
  };
}

class FrameSourceConformance : public ::testing::TestWithParam<SourceCase> {
 protected:
  void SetUp() override {
    auto made = GetParam().make(dir_.path(), &clock_);
    ASSERT_TRUE(made.ok()) << made.status().ToString();
    source_ = std::move(made).value();
  }

  ConfigureResult ConfigureNative(SourceConfig* granted) {
    SourceConfig wanted;
    wanted.pixel_format = PixelFormat::kRgb888;
    auto result = source_->Configure(wanted, granted);
    EXPECT_TRUE(result.ok()) << result.status().ToString();
    return result.ok() ? *result : ConfigureResult::kAdjusted;
  }

  testing::TempDir dir_;
  ManualClock clock_{1'000'000'000, 1'000'000};
  std::unique_ptr<FrameSource> source_;
};

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

INSTANTIATE_TEST_SUITE_P(EverySource, FrameSourceConformance, ::testing::ValuesIn(AllSources()),
                         [](const auto& param_info) { return param_info.param.name; });

}  // namespace
}  // namespace px
