#include "sim/synthetic/synthetic_source.h"

#include <gtest/gtest.h>

#include "sim/synthetic/scene_json.h"
#include "sim/synthetic/sim_test_util.h"

namespace px {
namespace {

using std::chrono::milliseconds;

SimCameraSpec SmallPop9() {
  SimCameraSpec spec = sim::testing::Quartered(sim::testing::Quartered(SimCameraSpec::Pop9()));
  spec.supersampling = 1;
  spec.noise_sigma = 2.0;
  spec.exposure_spread = 0.05;
  return spec;
}

SyntheticSourceOptions Options(ManualClock* clock) {
  SyntheticSourceOptions options;
  options.camera = SmallPop9();
  options.scene_file = sim::testing::SceneFile("still_life");
  options.seed = 42;
  options.clock = clock;
  return options;
}

std::unique_ptr<FrameSource> Make(const SyntheticSourceOptions& options) {
  auto made = MakeSyntheticSource(options);
  EXPECT_TRUE(made.ok()) << made.status().ToString();
  return made.ok() ? std::move(made).value() : nullptr;
}

TEST(SyntheticSourceTest, DescribesItselfAsTheSimulatedLattice) {
  ManualClock clock;
  auto source = Make(Options(&clock));
  ASSERT_NE(source, nullptr);
  EXPECT_EQ(source->Name(), "sim");
  const SourceDescription description = source->Describe();
  EXPECT_EQ(description.model, "sim:sim-pop9");
  EXPECT_EQ(description.kind, FrameSetKind::kLatticeFrame);
  ASSERT_TRUE(description.rig.has_value());
  EXPECT_TRUE(description.rig->Validate().ok());
  EXPECT_EQ(description.rig->NumViews(), 9);
  EXPECT_EQ(description.rig->lattice.sensor_width, SmallPop9().Layout().sensor_width);
}

TEST(SyntheticSourceTest, GrantsNativeSizeAndAnyFittingFormat) {
  ManualClock clock;
  auto source = Make(Options(&clock));
  ASSERT_NE(source, nullptr);
  const LatticeLayout layout = SmallPop9().Layout();
  SourceConfig granted;

  SourceConfig wanted{PixelFormat::kRgb888, 0, 0, 1};
  auto result = source->Configure(wanted, &granted);
  ASSERT_TRUE(result.ok());
  EXPECT_EQ(*result, ConfigureResult::kValid);  // 0 x 0 asks for the native size
  EXPECT_EQ(granted, (SourceConfig{PixelFormat::kRgb888, layout.sensor_width, layout.sensor_height, 1}));

  wanted = SourceConfig{PixelFormat::kNv12, layout.sensor_width, layout.sensor_height, 1};
  result = source->Configure(wanted, &granted);
  ASSERT_TRUE(result.ok());
  EXPECT_EQ(*result, ConfigureResult::kValid);
  EXPECT_EQ(granted, wanted);

  wanted = SourceConfig{PixelFormat::kBayerRggb8, 1920, 1080, 1};
  result = source->Configure(wanted, &granted);
  ASSERT_TRUE(result.ok());
  EXPECT_EQ(*result, ConfigureResult::kAdjusted);
  EXPECT_EQ(granted, (SourceConfig{PixelFormat::kBayerRggb8, layout.sensor_width, layout.sensor_height, 1}));

  wanted = SourceConfig{PixelFormat::kYuyv, 0, 0, 4};
  result = source->Configure(wanted, &granted);
  ASSERT_TRUE(result.ok());
  EXPECT_EQ(*result, ConfigureResult::kAdjusted);
  EXPECT_EQ(granted.shots, 1);
  auto frames = source->Next(milliseconds(1000));
  ASSERT_TRUE(frames.ok());
  EXPECT_EQ(frames->frames[0].image.format, PixelFormat::kYuyv);
  EXPECT_TRUE(CheckFrameSet(granted, &*frames).ok());
}

TEST(SyntheticSourceTest, NextNeedsConfigureAndEndsWithStop) {
  ManualClock clock;
  auto source = Make(Options(&clock));
  ASSERT_NE(source, nullptr);
  EXPECT_EQ(source->Next(milliseconds(1000)).status().code(), StatusCode::kFailedPrecondition);
  SourceConfig granted;
  ASSERT_TRUE(source->Configure(SourceConfig{}, &granted).ok());
  EXPECT_TRUE(source->Next(milliseconds(1000)).ok());
  source->Stop();
  source->Stop();
  EXPECT_EQ(source->Next(milliseconds(1000)).status().code(), StatusCode::kFailedPrecondition);
  ASSERT_TRUE(source->Configure(SourceConfig{}, &granted).ok());
  EXPECT_TRUE(source->Next(milliseconds(1000)).ok());
}

TEST(SyntheticSourceTest, CapturesAreStampedByTheClockAndCarryFreshNoise) {
  ManualClock clock(5'000'000'000, 1'000'000);
  const SyntheticSourceOptions options = Options(&clock);
  auto source = Make(options);
  ASSERT_NE(source, nullptr);
  SourceConfig granted;
  ASSERT_TRUE(source->Configure(SourceConfig{PixelFormat::kRgb888}, &granted).ok());
  auto first = source->Next(milliseconds(1000));
  auto second = source->Next(milliseconds(1000));
  ASSERT_TRUE(first.ok() && second.ok());
  ASSERT_EQ(first->frames.size(), 1u);
  EXPECT_EQ(first->kind, FrameSetKind::kLatticeFrame);
  EXPECT_EQ(first->frames[0].sequence, 0u);
  EXPECT_EQ(second->frames[0].sequence, 1u);
  EXPECT_GT(second->capture_id, first->capture_id);
  EXPECT_EQ(first->frames[0].timestamp_ns, 5'000'000'000);
  EXPECT_EQ(second->frames[0].timestamp_ns, 5'001'000'000);
  // Same scene and camera, new noise: the frames differ, though only by noise.
  EXPECT_NE(first->frames[0].image.bytes, second->frames[0].image.bytes);

  // The first capture is exactly what RenderSensorFrame makes with the same seed.
  auto scene = sim::LoadScene(options.scene_file);
  ASSERT_TRUE(scene.ok());
  auto reference = sim::RenderSensorFrame(*scene, options.camera, options.seed);
  ASSERT_TRUE(reference.ok());
  EXPECT_EQ(first->frames[0].image.bytes, reference->sensor.bytes);

  // A second source with the same seed repeats the same sequence of frames.
  ManualClock other_clock(5'000'000'000, 1'000'000);
  SyntheticSourceOptions again = options;
  again.clock = &other_clock;
  auto twin = Make(again);
  ASSERT_TRUE(twin->Configure(SourceConfig{PixelFormat::kRgb888}, &granted).ok());
  auto twin_first = twin->Next(milliseconds(1000));
  auto twin_second = twin->Next(milliseconds(1000));
  ASSERT_TRUE(twin_first.ok() && twin_second.ok());
  EXPECT_EQ(twin_first->frames[0].image.bytes, first->frames[0].image.bytes);
  EXPECT_EQ(twin_second->frames[0].image.bytes, second->frames[0].image.bytes);
}

TEST(SyntheticSourceTest, GroundTruthOfTheLastCapture) {
  ManualClock clock;
  const SyntheticSourceOptions options = Options(&clock);
  auto source = Make(options);
  ASSERT_NE(source, nullptr);
  EXPECT_EQ(LastGroundTruth(*source).status().code(), StatusCode::kFailedPrecondition);
  SourceConfig granted;
  ASSERT_TRUE(source->Configure(SourceConfig{}, &granted).ok());
  ASSERT_TRUE(source->Next(milliseconds(1000)).ok());
  ASSERT_TRUE(source->Next(milliseconds(1000)).ok());
  auto truth = LastGroundTruth(*source);
  ASSERT_TRUE(truth.ok()) << truth.status().ToString();
  EXPECT_EQ(truth->scene_name, "still_life");
  EXPECT_EQ(truth->noise_seed, sim::CaptureNoiseSeed(options.seed, 1));
  ASSERT_EQ(truth->views.size(), 9u);
  EXPECT_EQ(truth->exposure_gains, sim::DrawExposureGains(options.camera, options.seed));
  for (const sim::ViewTruth& view : truth->views) {
    EXPECT_EQ(view.bgr.size(), cv::Size(options.camera.tile_width, options.camera.tile_height));
    EXPECT_EQ(view.depth_m.type(), CV_32F);
    EXPECT_GT(cv::countNonZero(view.depth_m > 0), view.depth_m.total() * 99 / 100);
  }
  // Scribbling on the returned images does not touch the source's cache.
  truth->views[0].bgr.setTo(cv::Scalar::all(0));
  auto again = LastGroundTruth(*source);
  ASSERT_TRUE(again.ok());
  EXPECT_GT(cv::norm(again->views[0].bgr, cv::NORM_L1), 0.0);
}

class NotSynthetic final : public FrameSource {
 public:
  std::string_view Name() const override { return "other"; }
  SourceDescription Describe() const override { return {}; }
  StatusOr<ConfigureResult> Configure(const SourceConfig&, SourceConfig*) override { return ConfigureResult::kValid; }
  StatusOr<FrameSet> Next(std::chrono::milliseconds) override { return UnavailableError("none"); }
  void Stop() override {}
};

TEST(SyntheticSourceTest, GroundTruthOnlyFromSyntheticSources) {
  NotSynthetic other;
  EXPECT_EQ(LastGroundTruth(other).status().code(), StatusCode::kInvalidArgument);
}

TEST(SyntheticSourceTest, CreationErrorsNameTheProblem) {
  ManualClock clock;
  SyntheticSourceOptions options = Options(&clock);
  options.scene_file = "/nonexistent/scene.json";
  auto made = MakeSyntheticSource(options);
  ASSERT_FALSE(made.ok());
  EXPECT_EQ(made.status().code(), StatusCode::kNotFound);
  EXPECT_NE(made.status().message().find("/nonexistent/scene.json"), std::string::npos);

  options = Options(&clock);
  options.camera.baseline_m = -1;
  made = MakeSyntheticSource(options);
  ASSERT_FALSE(made.ok());
  EXPECT_NE(made.status().message().find("baseline_m"), std::string::npos);

  // No scene file: the default scene.
  options = Options(&clock);
  options.scene_file.clear();
  EXPECT_TRUE(MakeSyntheticSource(options).ok());
}

}  // namespace
}  // namespace px
