// The worker runner with the real parallaxd as its worker and a real simulated capture: the clip
// is made in the child and progress relayed; a worker over its memory or time limit is killed
// and reported as ABORTED with the limit and the stage; a cancel stops it with CANCELLED.
#include "device/worker/worker_runner.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <set>

#include "capture/recording.h"
#include "device/config.h"
#include "device/source_registry.h"
#include "device/test_pause.h"
#include "sim/synthetic/synthetic_source.h"
#include "tests/testing/temp_dir.h"
#include "tests/testing/video_probe.h"

namespace px::device {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

class WorkerRunnerTest : public px::testing::TempDirTest {
 protected:
  void SetUp() override {
    SimSourceSettings sim;
    sim.tile_width = 160;
    sim.tile_height = 120;
    SyntheticSourceOptions source_options;
    source_options.camera = SimCameraFromSettings(sim).value();
    auto source = MakeSyntheticSource(source_options).value();
    SourceConfig granted;
    ASSERT_TRUE(source->Configure({source_options.camera.pixel_format, 0, 0, 1}, &granted).ok());
    const Recording recording{source->Describe(), source->Next(std::chrono::seconds(10)).value(), "worker test"};
    ASSERT_TRUE(WriteRecording(dir() / "capture", recording).ok());
    fs::create_directories(dir() / "clips");
  }

  WorkerRunnerOptions Options() const {
    DaemonConfig config;
    config.clip.duration_s = 0.3;
    config.clip.fps = 10;
    config.clip.preset = "ultrafast";
    config.clip.num_threads = 2;
    WorkerRunnerOptions options;
    options.binary = fs::path(PX_BINARY_DIR) / "parallaxd";
    options.config = DaemonConfigToJson(config);
    return options;
  }

  JobContext Context() {
    JobContext context;
    context.job_id = "000001";
    context.capture_dir = dir() / "capture";
    context.clip_path = dir() / "clips" / "000001.mp4";
    context.progress = [this](const std::string& stage, double) {
      stages_.insert(stage);
      return true;
    };
    context.worker = [this](int pid) { worker_pids_.push_back(pid); };
    return context;
  }

  std::set<std::string> stages_;
  std::vector<int> worker_pids_;
};

TEST_F(WorkerRunnerTest, TheClipIsMadeInAChildProcessThatReportsItsProgress) {
  const JobContext context = Context();
  StatusOr<JobOutcome> outcome = MakeWorkerJobRunner(Options())(context);
  ASSERT_TRUE(outcome.ok()) << outcome.status().ToString();
  EXPECT_THAT(outcome->note, HasSubstr("3 frames 160x120, 9 views"));
  EXPECT_EQ(outcome->clip_path, context.clip_path);
  auto video = px::testing::ProbeVideo(context.clip_path);
  ASSERT_TRUE(video.ok()) << video.status().ToString();
  EXPECT_EQ(video->frames_decoded, 3);
  EXPECT_TRUE(stages_.count("depth") == 1 && stages_.count("render") == 1) << "progress was not relayed";
  ASSERT_EQ(worker_pids_.size(), 2u);
  EXPECT_GT(worker_pids_[0], 0);
  EXPECT_NE(worker_pids_[0], ::getpid());
  EXPECT_EQ(worker_pids_[1], 0);
}

TEST_F(WorkerRunnerTest, AWorkerOverItsMemoryLimitIsKilledAndReportedAsAborted) {
  WorkerRunnerOptions options = Options();
  options.memory_limit_bytes = 48ull << 20;  // a worker holds more than this once its libraries are in
  StatusOr<JobOutcome> outcome = MakeWorkerJobRunner(options)(Context());
  ASSERT_FALSE(outcome.ok());
  EXPECT_EQ(outcome.status().code(), StatusCode::kAborted) << outcome.status().ToString();
  EXPECT_THAT(outcome.status().message(), HasSubstr("over its limit of 48 MB (worker.memory_limit_mb)"));
  EXPECT_FALSE(fs::exists(dir() / "clips" / "000001.mp4"));
}

TEST_F(WorkerRunnerTest, AWorkerPastItsTimeLimitIsKilledAndTheStageNamed) {
  ::setenv(kTestPauseEnv, "depth", 1);  // inherited by the worker, which then hangs in depth
  WorkerRunnerOptions options = Options();
  options.timeout = std::chrono::seconds(3);
  StatusOr<JobOutcome> outcome = MakeWorkerJobRunner(options)(Context());
  ::unsetenv(kTestPauseEnv);
  ASSERT_FALSE(outcome.ok());
  EXPECT_EQ(outcome.status().code(), StatusCode::kAborted) << outcome.status().ToString();
  EXPECT_THAT(outcome.status().message(), HasSubstr("ran past its limit of 3 s (worker.timeout_s) during depth"));
}

TEST_F(WorkerRunnerTest, ACancelStopsTheWorkerWhichReturnsCancelled) {
  JobContext context = Context();
  context.progress = [](const std::string& stage, double) { return stage != "depth"; };
  StatusOr<JobOutcome> outcome = MakeWorkerJobRunner(Options())(context);
  ASSERT_FALSE(outcome.ok());
  EXPECT_EQ(outcome.status().code(), StatusCode::kCancelled) << outcome.status().ToString();
  EXPECT_FALSE(fs::exists(context.clip_path));
}

TEST_F(WorkerRunnerTest, AWorkerThatCannotStartIsAnErrorNamingTheBinary) {
  WorkerRunnerOptions options = Options();
  options.binary = dir() / "no-such-parallaxd";
  StatusOr<JobOutcome> outcome = MakeWorkerJobRunner(options)(Context());
  ASSERT_FALSE(outcome.ok());
  EXPECT_THAT(outcome.status().ToString(), HasSubstr("no-such-parallaxd"));
}

}  // namespace
}  // namespace px::device
