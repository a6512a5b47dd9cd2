// Crash tests: the real parallaxd (simulated camera, 160x120 tiles, 0.3 s clips at 10 fps) is
// killed with SIGKILL at every phase of a job that device/test_pause.h names, and at a random
// moment, then started again on the same storage. Each run checks (README "Crash tests"):
//   - nothing half-written is visible: every visible clip decodes whole with its report beside
//     it, every captures/<id> with a manifest reads back as a valid recording (frames checked
//     against their SHA-256), and after the restart no temporary is left anywhere;
//   - the raw capture survives whenever it was saved before the kill;
//   - the interrupted job is resumed and finishes (done), or, when its capture was never saved,
//     is failed with the reason;
//   - the restarted daemon answers status and the next press makes a clip.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <thread>

#include "capture/recording.h"
#include "device/process/daemon_process.h"
#include "device/storage/storage_layout.h"
#include "device/test_pause.h"
#include "pipeline/io/durable_file.h"
#include "tests/testing/temp_dir.h"
#include "tests/testing/video_probe.h"

namespace px::device {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using ::testing::HasSubstr;

constexpr int kClipFrames = 3;  // 0.3 s at 10 fps

struct Phase {
  const char* name;
  bool saved;  // the recording is complete on disk when the daemon stops there
};

// In a job's order (test_pause.h).
constexpr Phase kPhases[] = {
    {"capture", false},
    {"writing_capture", false},
    {"saved", true},
    {"depth", true},
    {"render", true},
    {"encode", true},
    {"clip_written", true},
};

class ParallaxdCrashTest : public px::testing::TempDirTest {
 protected:
  void SetUp() override {
    layout_ = std::make_unique<StorageLayout>(dir() / "store");
    const nlohmann::json config = {
        {"storage", {{"root", layout_->root().string()}, {"min_free_mb", 0}}},
        {"control", {{"socket", Socket().string()}}},
        {"source", {{"sim", {{"tile_width", 160}, {"tile_height", 120}}}}},
        {"clip", {{"duration_s", 0.3}, {"fps", 10}, {"preset", "ultrafast"}, {"num_threads", 2}}},
    };
    ASSERT_TRUE(WriteFileAtomically(ConfigPath(), config.dump(2)).ok());
  }
  fs::path Socket() const { return dir() / "ctl.sock"; }
  fs::path ConfigPath() const { return dir() / "parallaxd.json"; }

  // pause_at: "" = run normally.
  std::unique_ptr<DaemonProcess> Launch(const std::string& pause_at, const std::string& log_name) {
    DaemonProcessOptions options;
    options.binary = fs::path(PX_BINARY_DIR) / "parallaxd";
    options.args = {"--config", ConfigPath().string()};
    options.env = {{kTestPauseEnv, pause_at.empty() ? std::nullopt : std::optional<std::string>(pause_at)},
                   {"PARALLAX_CONFIG", std::nullopt},
                   {"NOTIFY_SOCKET", std::nullopt},
                   {"WATCHDOG_USEC", std::nullopt}};
    options.log_path = dir() / log_name;
    auto process = DaemonProcess::Start(options);
    EXPECT_TRUE(process.ok()) << process.status().ToString();
    return process.ok() ? std::move(process).value() : nullptr;
  }

  static nlohmann::json Call(ControlClient& client,
                             const std::string& request,
                             std::chrono::milliseconds timeout = 10s) {
    auto reply = client.Call(request, timeout);
    EXPECT_TRUE(reply.ok()) << request << ": " << reply.status().ToString();
    return reply.ok() ? nlohmann::json::parse(*reply) : nlohmann::json(nullptr);
  }

  // Presses once; the job id.
  static std::string Press(ControlClient& client) {
    const nlohmann::json reply = Call(client, R"({"cmd":"capture"})");
    EXPECT_EQ(reply["ok"], true) << reply.dump();
    return reply.value("job", "");
  }

  static nlohmann::json WaitJob(ControlClient& client, const std::string& id) {
    const nlohmann::json reply = Call(client, R"({"cmd":"wait","job":")" + id + R"("})", 180s);
    EXPECT_EQ(reply["ok"], true) << reply.dump();
    return reply.is_object() ? reply.value("job", nlohmann::json::object()) : nlohmann::json::object();
  }

  bool CaptureSaved(const std::string& id) const { return fs::exists(layout_->CaptureDir(id) / "manifest.json"); }

  // What a reader may see at any moment: whole clips (with reports) and valid recordings.
  // Temporaries (hidden, ".<stem>.tmp-<pid>-<n>") are allowed only when `allow_temporaries`.
  void ExpectNothingHalfWritten(bool allow_temporaries, const std::string& when) {
    std::error_code ec;
    for (fs::recursive_directory_iterator it(layout_->root(), ec), end; !ec && it != end; it.increment(ec)) {
      const std::string name = it->path().filename().string();
      if (name.find(".tmp-") != std::string::npos) {
        EXPECT_TRUE(allow_temporaries) << when << ": temporary left behind: " << it->path();
        EXPECT_EQ(name.front(), '.') << when << ": a temporary must be hidden: " << it->path();
      }
    }
    for (fs::directory_iterator it(layout_->ClipsDir(), ec), end; !ec && it != end; it.increment(ec)) {
      const fs::path path = it->path();
      if (path.filename().string().front() == '.' || path.extension() != ".mp4") continue;
      auto video = px::testing::ProbeVideo(path);
      ASSERT_TRUE(video.ok()) << when << ": visible clip " << path << " is not whole: " << video.status().ToString();
      EXPECT_EQ(video->frames_decoded, kClipFrames) << when << ": " << path;
      EXPECT_TRUE(fs::exists(ClipReportPathFor(path))) << when << ": clip without its report: " << path;
    }
    for (fs::directory_iterator it(layout_->CapturesDir(), ec), end; !ec && it != end; it.increment(ec)) {
      if (!fs::exists(it->path() / "manifest.json")) continue;  // not a recording (yet): never read as one
      auto recording = ReadRecording(it->path());
      EXPECT_TRUE(recording.ok()) << when << ": " << it->path() << ": " << recording.status().ToString();
    }
  }

  // Restarts on the same storage and checks the interrupted job `id` and one more press.
  void RestartAndCheck(const std::string& id, bool saved, const std::string& when) {
    auto daemon = Launch("", "after-" + when + ".log");
    ASSERT_NE(daemon, nullptr);
    auto client = daemon->Connect(Socket(), 60s);
    ASSERT_TRUE(client.ok()) << client.status().ToString();
    const nlohmann::json job = WaitJob(**client, id);
    if (saved) {
      EXPECT_EQ(job.value("state", ""), "done") << when << ": " << job.dump() << "\n" << daemon->Log();
      auto video = px::testing::ProbeVideo(layout_->ClipPath(id));
      EXPECT_TRUE(video.ok()) << when << ": " << video.status().ToString();
      EXPECT_TRUE(ReadRecording(layout_->CaptureDir(id)).ok()) << when << ": the raw capture must survive";
    } else {
      EXPECT_EQ(job.value("state", ""), "failed") << when << ": " << job.dump();
      // Killed before the recording was written, or while it was (the unfinished one is removed).
      EXPECT_THAT(job.value("error", ""),
                  ::testing::AnyOf(HasSubstr("the daemon stopped before the capture was saved"),
                                   HasSubstr("the daemon stopped while the capture was being written")))
          << when;
      EXPECT_FALSE(fs::exists(layout_->ClipPath(id))) << when;
    }
    const nlohmann::json status = Call(**client, R"({"cmd":"status"})");
    EXPECT_EQ(status["ok"], true) << when << ": " << status.dump();
    const std::string next = Press(**client);
    const nlohmann::json next_job = WaitJob(**client, next);
    EXPECT_EQ(next_job.value("state", ""), "done") << when << ": the next press: " << next_job.dump();
    EXPECT_EQ(Call(**client, R"({"cmd":"quit"})")["ok"], true);
    auto exit_code = daemon->WaitExit(60s);
    ASSERT_TRUE(exit_code.ok()) << exit_code.status().ToString();
    EXPECT_EQ(*exit_code, 0) << daemon->Log();
    ExpectNothingHalfWritten(/*allow_temporaries=*/false, "after restart (" + when + ")");
  }

  // The pid of the worker process of the job being processed, once there is one (polls status).
  static pid_t WorkerPid(ControlClient& client, pid_t not_this = 0) {
    for (int i = 0; i < 600; ++i) {
      const nlohmann::json status = Call(client, R"({"cmd":"status"})");
      const nlohmann::json& processing = status["processing"];
      if (processing.is_object() && processing["worker_pid"].is_number_integer()) {
        const pid_t pid = processing["worker_pid"].get<pid_t>();
        if (pid != not_this) return pid;
      }
      std::this_thread::sleep_for(100ms);
    }
    ADD_FAILURE() << "no worker process showed in status within 60 s";
    return 0;
  }

  // Polls until `text` occurs `times` times in the daemon's log (its workers log there too).
  static void WaitForLogCount(DaemonProcess& daemon, const std::string& text, int times) {
    for (int i = 0; i < 1200; ++i) {
      const std::string log = daemon.Log();
      int found = 0;
      for (size_t at = log.find(text); at != std::string::npos; at = log.find(text, at + 1)) ++found;
      if (found >= times) return;
      std::this_thread::sleep_for(100ms);
    }
    FAIL() << "'" << text << "' did not appear " << times << " times within 120 s:\n" << daemon.Log();
  }

  // A process that has ended: gone from /proc, or a zombie nobody has reaped yet.
  static bool Ended(pid_t pid) {
    std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
    std::string pid_field;
    std::string name;
    std::string state;
    return !(stat >> pid_field >> name >> state) || state == "Z" || state == "X";
  }

  std::unique_ptr<StorageLayout> layout_;
};

class KillAtPhase : public ParallaxdCrashTest, public ::testing::WithParamInterface<Phase> {};

TEST_P(KillAtPhase, CaptureSurvivesJobResumesAndNextPressWorks) {
  const Phase phase = GetParam();
  auto daemon = Launch(phase.name, "paused.log");
  ASSERT_NE(daemon, nullptr);
  auto client = daemon->Connect(Socket(), 60s);
  ASSERT_TRUE(client.ok()) << client.status().ToString();
  const std::string id = Press(**client);
  ASSERT_EQ(id, "000001");
  const Status paused = daemon->WaitForLog(std::string("paused at ") + phase.name, 120s);
  ASSERT_TRUE(paused.ok()) << paused.ToString();
  ASSERT_TRUE(daemon->KillHard().ok());
  client->reset();

  EXPECT_EQ(CaptureSaved(id), phase.saved) << phase.name;
  if (std::string(phase.name) == "clip_written") {
    EXPECT_TRUE(fs::exists(layout_->ClipPath(id))) << "the clip was in place before the journal said done";
  }
  if (std::string(phase.name) == "encode") {
    EXPECT_FALSE(fs::exists(layout_->ClipPath(id))) << "the clip must not appear before its rename";
  }
  ExpectNothingHalfWritten(/*allow_temporaries=*/true, std::string("killed at ") + phase.name);
  RestartAndCheck(id, phase.saved, phase.name);
}

INSTANTIATE_TEST_SUITE_P(EveryPhase,
                         KillAtPhase,
                         ::testing::ValuesIn(kPhases),
                         [](const ::testing::TestParamInfo<Phase>& param_info) {
                           return std::string(param_info.param.name);
                         });

TEST_F(ParallaxdCrashTest, KillAtARandomMoment) {
  // A fresh seed each run (printed, and settable to repeat one): over many CI runs the kill
  // lands everywhere, including between the phases the hook names.
  const char* seed_env = std::getenv("PX_CRASH_SEED");
  const uint64_t seed = seed_env != nullptr ? std::strtoull(seed_env, nullptr, 10) : std::random_device{}();
  std::mt19937_64 rng(seed);
  const auto delay = std::chrono::milliseconds(std::uniform_int_distribution<int>(0, 2500)(rng));
  std::cout << "PX_CRASH_SEED=" << seed << ": SIGKILL " << delay.count() << " ms after the press\n";

  auto daemon = Launch("", "random.log");
  ASSERT_NE(daemon, nullptr);
  auto client = daemon->Connect(Socket(), 60s);
  ASSERT_TRUE(client.ok()) << client.status().ToString();
  const std::string id = Press(**client);
  std::this_thread::sleep_for(delay);
  ASSERT_TRUE(daemon->KillHard().ok());
  client->reset();
  const bool saved = CaptureSaved(id);
  std::cout << "capture " << (saved ? "was" : "was not") << " saved when killed\n";
  ExpectNothingHalfWritten(/*allow_temporaries=*/true, "killed at random");
  RestartAndCheck(id, saved, "random");
}

// The daemon never runs the pipeline itself: a worker process killed by a signal mid-stage costs
// the job an attempt, never the daemon. The job is retried, then failed after worker.max_crashes
// with the signal and the stage named, its raw capture kept, and the daemon still takes presses.
class WorkerKilled : public ParallaxdCrashTest, public ::testing::WithParamInterface<int> {};

TEST_P(WorkerKilled, TheJobIsRetriedThenFailedWithItsCaptureKeptAndTheDaemonStaysUp) {
  const int signal = GetParam();
  const std::string signal_name = signal == SIGSEGV ? "SIGSEGV" : "SIGKILL";
  auto daemon = Launch("depth", "worker-" + signal_name + ".log");
  ASSERT_NE(daemon, nullptr);
  auto client = daemon->Connect(Socket(), 60s);
  ASSERT_TRUE(client.ok()) << client.status().ToString();
  const std::string id = Press(**client);
  pid_t worker = 0;
  for (int crash = 1; crash <= 3; ++crash) {  // worker.max_crashes is 3 by default
    WaitForLogCount(*daemon, "paused at depth", crash);
    worker = WorkerPid(**client, worker);
    ASSERT_GT(worker, 0);
    ASSERT_NE(worker, daemon->pid());
    std::cout << "crash " << crash << ": " << signal_name << " to worker " << worker << "\n";
    ASSERT_EQ(::kill(worker, signal), 0);
  }
  const nlohmann::json job = WaitJob(**client, id);
  EXPECT_EQ(job.value("state", ""), "failed") << job.dump();
  EXPECT_EQ(job.value("worker_crashes", 0), 3) << job.dump();
  EXPECT_THAT(job.value("error", ""), HasSubstr("ABORTED: the worker was killed by " + signal_name + " during depth"));
  EXPECT_THAT(job.value("error", ""), HasSubstr("failed after 3 worker crash(es)"));
  EXPECT_TRUE(ReadRecording(layout_->CaptureDir(id)).ok()) << "the raw capture must be kept";
  EXPECT_FALSE(fs::exists(layout_->ClipPath(id)));
  EXPECT_TRUE(daemon->running()) << "a worker's crash must not take the daemon down";
  EXPECT_EQ(Call(**client, R"({"cmd":"status"})")["ok"], true);
  ExpectNothingHalfWritten(/*allow_temporaries=*/false, "after the worker crashes");
  ASSERT_TRUE(daemon->KillHard().ok());
}

INSTANTIATE_TEST_SUITE_P(BySignal,
                         WorkerKilled,
                         ::testing::Values(SIGSEGV, SIGKILL),
                         [](const ::testing::TestParamInfo<int>& param_info) {
                           return std::string(param_info.param == SIGSEGV ? "SIGSEGV" : "SIGKILL");
                         });

// A daemon killed again and again while the same job runs (a restart loop, a flaky power supply)
// is not the job's fault: the job resumes every time and is finally made. Its worker dies with
// the daemon each time rather than writing a clip nobody journals.
TEST_F(ParallaxdCrashTest, TheDaemonKilledTenTimesDuringAJobStillMakesItsClip) {
  std::string id;
  for (int kill = 1; kill <= 10; ++kill) {
    auto daemon = Launch("depth", "killed-" + std::to_string(kill) + ".log");
    ASSERT_NE(daemon, nullptr);
    auto client = daemon->Connect(Socket(), 60s);
    ASSERT_TRUE(client.ok()) << client.status().ToString();
    if (kill == 1) id = Press(**client);
    WaitForLogCount(*daemon, "paused at depth", 1);
    const pid_t worker = WorkerPid(**client);
    ASSERT_GT(worker, 0);
    ASSERT_TRUE(daemon->KillHard().ok());
    bool ended = false;
    for (int i = 0; i < 50 && !ended; ++i) {
      ended = Ended(worker);
      if (!ended) std::this_thread::sleep_for(100ms);
    }
    EXPECT_TRUE(ended) << "kill " << kill << ": worker " << worker << " outlived its daemon";
    ExpectNothingHalfWritten(/*allow_temporaries=*/true, "daemon killed " + std::to_string(kill) + " times");
  }
  auto daemon = Launch("", "finally.log");
  ASSERT_NE(daemon, nullptr);
  auto client = daemon->Connect(Socket(), 60s);
  ASSERT_TRUE(client.ok()) << client.status().ToString();
  const nlohmann::json job = WaitJob(**client, id);
  EXPECT_EQ(job.value("state", ""), "done") << job.dump() << "\n" << daemon->Log();
  EXPECT_EQ(job.value("attempts", 0), 11) << job.dump();
  EXPECT_EQ(job.value("worker_crashes", -1), 0) << job.dump();
  EXPECT_TRUE(px::testing::ProbeVideo(layout_->ClipPath(id)).ok());
  EXPECT_EQ(Call(**client, R"({"cmd":"quit"})")["ok"], true);
  auto exit_code = daemon->WaitExit(60s);
  ASSERT_TRUE(exit_code.ok()) << exit_code.status().ToString();
  EXPECT_EQ(*exit_code, 0);
  ExpectNothingHalfWritten(/*allow_temporaries=*/false, "after the last restart");
}

}  // namespace
}  // namespace px::device
