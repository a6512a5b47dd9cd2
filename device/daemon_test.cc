// The daemon's state machine, driven through its real control socket and trigger input, with a
// small deterministic source and a simple but real job (decode the saved recording, write its
// first frame as a PNG). The full pipeline runs in daemon_integration_test.cc.
#include "device/daemon.h"

#include <fcntl.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <atomic>
#include <future>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <span>

#include "capture/recording.h"
#include "capture/sha256.h"
#include "device/clip_fetch.h"
#include "device/control/control_client.h"
#include "device/control/control_protocol.h"
#include "pipeline/io/durable_file.h"
#include "tests/testing/temp_dir.h"

namespace px::device {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

constexpr int kWidth = 64;
constexpr int kHeight = 48;

// A 64x48 BGR sensor whose frame k is a gradient offset by k; `fail_next` makes the next
// captures fail as a vanished camera does.
class GradientSource final : public FrameSource {
 public:
  std::string_view Name() const override { return "gradient"; }
  SourceDescription Describe() const override { return {"test:gradient", FrameSetKind::kLatticeFrame, std::nullopt}; }
  StatusOr<ConfigureResult> Configure(const SourceConfig& wanted, SourceConfig* granted) override {
    *granted = {PixelFormat::kBgr888, kWidth, kHeight, 1};
    configures++;
    return wanted == *granted ? ConfigureResult::kValid : ConfigureResult::kAdjusted;
  }
  StatusOr<FrameSet> Next(std::chrono::milliseconds) override {
    while (hold) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    if (fail_next > 0) {
      fail_next--;
      return UnavailableError("sensor disconnected");
    }
    cv::Mat bgr(kHeight, kWidth, CV_8UC3);
    for (int y = 0; y < kHeight; ++y) {
      for (int x = 0; x < kWidth; ++x) bgr.at<cv::Vec3b>(y, x) = cv::Vec3b(x * 4, y * 5, (x + y + count) % 256);
    }
    FrameSet set;
    set.capture_id = ++count;
    Frame frame;
    frame.image = FromBgr(bgr, PixelFormat::kBgr888).value();
    frame.sequence = count;
    frame.timestamp_ns = count * 1'000'000;
    set.frames.push_back(std::move(frame));
    return set;
  }
  void Stop() override {}

  std::atomic<int> fail_next{0};
  std::atomic<int> configures{0};
  std::atomic<bool> hold{false};  // Next waits while set
  uint64_t count = 0;
};

// The simple real job: decode the recording and write its first frame, as PNG, where the clip goes.
StatusOr<JobOutcome> PngJob(const JobContext& context) {
  PX_ASSIGN_OR_RETURN(Recording recording, ReadRecording(context.capture_dir));
  PX_ASSIGN_OR_RETURN(cv::Mat bgr, ToBgr(recording.frames.frames.at(0).image));
  std::vector<uint8_t> png;
  if (!cv::imencode(".png", bgr, png)) return InternalError("png encode failed");
  PX_RETURN_IF_ERROR(WriteFileAtomically(context.clip_path, std::string(png.begin(), png.end())));
  return JobOutcome{std::to_string(png.size()) + " bytes"};
}

class DaemonTest : public px::testing::TempDirTest {
 protected:
  DaemonOptions Options() {
    DaemonOptions options;
    options.storage.root = dir() / "store";
    options.storage.min_free_bytes = 0;
    options.control_socket = dir() / "ctl.sock";
    options.wanted_source = SourceConfig{PixelFormat::kBgr888, kWidth, kHeight, 1};
    options.created_by = "daemon_test";
    return options;
  }
  std::unique_ptr<Daemon> StartDaemon(DaemonOptions options, JobRunner runner = PngJob) {
    auto source = std::make_unique<GradientSource>();
    source_ = source.get();
    auto daemon = std::make_unique<Daemon>(std::move(options), std::move(source), std::move(runner));
    daemon->SetClipListener([this](const fs::path& clip) {
      std::lock_guard<std::mutex> lock(clips_mutex_);
      clips_.push_back(clip);
    });
    Status started = daemon->Start();
    EXPECT_TRUE(started.ok()) << started.ToString();
    return daemon;
  }
  nlohmann::json Call(const std::string& request) {
    auto client = ControlClient::Connect(dir() / "ctl.sock");
    EXPECT_TRUE(client.ok()) << client.status().ToString();
    if (!client.ok()) return nullptr;
    auto reply = (*client)->Call(request);
    EXPECT_TRUE(reply.ok()) << reply.status().ToString();
    return reply.ok() ? nlohmann::json::parse(*reply) : nlohmann::json(nullptr);
  }
  std::vector<fs::path> Clips() {
    std::lock_guard<std::mutex> lock(clips_mutex_);
    return clips_;
  }

  GradientSource* source_ = nullptr;
  std::mutex clips_mutex_;
  std::vector<fs::path> clips_;
};

TEST_F(DaemonTest, PressThroughSocketSavesCaptureThenMakesClip) {
  auto daemon = StartDaemon(Options());
  nlohmann::json reply = Call(R"({"cmd":"capture"})");
  ASSERT_EQ(reply["ok"], true) << reply.dump();
  const std::string id = reply["job"];
  EXPECT_EQ(id, "000001");

  nlohmann::json waited = Call(R"({"cmd":"wait","job":")" + id + R"("})");
  ASSERT_EQ(waited["ok"], true) << waited.dump();
  EXPECT_EQ(waited["job"]["state"], "done");

  // The raw capture is a valid recording holding what the source delivered.
  auto recording = ReadRecording(daemon->layout().CaptureDir(id));
  ASSERT_TRUE(recording.ok()) << recording.status().ToString();
  EXPECT_EQ(recording->frames.frames.size(), 1u);
  EXPECT_EQ(recording->source.model, "test:gradient");
  EXPECT_EQ(recording->created_by, "daemon_test");
  // The "clip" is that frame, and it was announced with its absolute path.
  const fs::path clip = daemon->layout().ClipPath(id);
  cv::Mat png = cv::imread(clip.string(), cv::IMREAD_COLOR);
  ASSERT_FALSE(png.empty());
  EXPECT_EQ(cv::norm(png, ToBgr(recording->frames.frames[0].image).value(), cv::NORM_INF), 0);
  EXPECT_EQ(Clips(), std::vector<fs::path>{clip});
  EXPECT_TRUE(clip.is_absolute());

  nlohmann::json status = Call(R"({"cmd":"status"})");
  EXPECT_EQ(status["state"], "idle");
  EXPECT_EQ(status["jobs"]["done"], 1);
  EXPECT_EQ(status["last_job"]["id"], id);
  EXPECT_EQ(status["last_job"]["state"], "done");
  EXPECT_EQ(status["last_job"]["clip_path"], clip.string());
  EXPECT_EQ(status["source"], "test:gradient");
  nlohmann::json list = Call(R"({"cmd":"list"})");
  ASSERT_EQ(list["jobs"].size(), 1u);
  EXPECT_EQ(list["jobs"][0]["capture_dir"], daemon->layout().CaptureDir(id).string());
  EXPECT_EQ(list["jobs"][0]["attempts"], 1);
}

TEST_F(DaemonTest, MalformedRequestsGetErrorsAndTheDaemonStaysUp) {
  auto daemon = StartDaemon(Options());
  auto client = ControlClient::Connect(dir() / "ctl.sock").value();
  for (const std::string& bad : {std::string("this is not json"),
                                 std::string(R"({"cmd":"fly"})"),
                                 std::string(R"({"cmd":"wait","job":"999999"})"),
                                 std::string("{\"cmd\":")}) {
    auto reply = client->Call(bad);
    ASSERT_TRUE(reply.ok()) << reply.status().ToString();
    nlohmann::json j = nlohmann::json::parse(*reply);
    EXPECT_EQ(j["ok"], false) << bad;
    EXPECT_FALSE(j["error"].get<std::string>().empty());
  }
  EXPECT_THAT(client->Call(R"({"cmd":"wait","job":"999999"})").value(), HasSubstr("no such job"));
  // Blank lines are ignored; two requests in one write are answered in order.
  ASSERT_TRUE(client->SendRaw("\n  \n{\"cmd\":\"status\"}\n{\"cmd\":\"list\"}\n").ok());
  EXPECT_THAT(client->ReadLine(std::chrono::seconds(10)).value(), HasSubstr("\"state\":"));
  EXPECT_THAT(client->ReadLine(std::chrono::seconds(10)).value(), HasSubstr("\"jobs\":[]"));
  // A line longer than the limit is refused and that connection dropped; others still work.
  ASSERT_TRUE(client->SendRaw(std::string(kMaxControlLineBytes + 10, 'x')).ok());
  EXPECT_THAT(client->ReadLine(std::chrono::seconds(10)).value(), HasSubstr("longer than"));
  EXPECT_EQ(Call(R"({"cmd":"capture"})")["ok"], true);
  daemon->WaitUntilIdle();
  EXPECT_EQ(Call(R"({"cmd":"status"})")["jobs"]["done"], 1);
}

TEST_F(DaemonTest, CameraFailureFailsOnlyThatJob) {
  auto daemon = StartDaemon(Options());
  source_->fail_next = 1;
  const std::string bad = Call(R"({"cmd":"capture"})")["job"];
  const std::string good = Call(R"({"cmd":"capture"})")["job"];
  nlohmann::json failed = Call(R"({"cmd":"wait","job":")" + bad + R"("})");
  EXPECT_EQ(failed["job"]["state"], "failed");
  EXPECT_THAT(failed["job"]["error"].get<std::string>(), HasSubstr("sensor disconnected"));
  EXPECT_FALSE(fs::exists(daemon->layout().CaptureDir(bad)));
  EXPECT_EQ(Call(R"({"cmd":"wait","job":")" + good + R"("})")["job"]["state"], "done");
  // The camera was configured again after it vanished.
  EXPECT_EQ(source_->configures.load(), 2);
}

TEST_F(DaemonTest, FailedProcessingKeepsTheRawCapture) {
  auto daemon = StartDaemon(
      Options(), [](const JobContext&) -> StatusOr<JobOutcome> { return DataLossError("depth: no plane found"); });
  const std::string id = Call(R"({"cmd":"capture"})")["job"];
  nlohmann::json job = Call(R"({"cmd":"wait","job":")" + id + R"("})")["job"];
  EXPECT_EQ(job["state"], "failed");
  EXPECT_EQ(job["error"], "DATA_LOSS: depth: no plane found");
  EXPECT_TRUE(ReadRecording(daemon->layout().CaptureDir(id)).ok());
  EXPECT_FALSE(fs::exists(daemon->layout().ClipPath(id)));
  EXPECT_TRUE(Clips().empty());
}

TEST_F(DaemonTest, PressesWhileProcessingAreQueuedNotLost) {
  std::promise<void> release;
  std::shared_future<void> released = release.get_future().share();
  std::promise<void> first_started;
  std::atomic<int> runs{0};
  auto daemon = StartDaemon(Options(), [&](const JobContext& context) {
    if (runs++ == 0) {
      first_started.set_value();
      released.wait();  // hold the worker on the first job while more presses arrive
    }
    return PngJob(context);
  });
  std::vector<std::string> ids = {Call(R"({"cmd":"capture"})")["job"]};
  first_started.get_future().wait();
  for (int i = 0; i < 4; ++i) ids.push_back(Call(R"({"cmd":"capture"})")["job"]);
  nlohmann::json status = Call(R"({"cmd":"status"})");
  EXPECT_EQ(status["processing"]["job"], ids[0]);
  release.set_value();
  daemon->WaitUntilIdle();
  for (const std::string& id : ids) {
    EXPECT_EQ(daemon->Job(id)->state, JobState::kDone) << id;
    EXPECT_TRUE(fs::exists(daemon->layout().ClipPath(id))) << id;
  }
  EXPECT_EQ(Clips().size(), 5u);
}

TEST_F(DaemonTest, StdinTriggerPressesPerLineAndStopsAfterDrainingAtEof) {
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  DaemonOptions options = Options();
  options.control_socket.clear();
  options.trigger_fd = fds[0];
  auto daemon = StartDaemon(options);
  ASSERT_EQ(::write(fds[1], "\n\nlast line without newline", 28), 28);
  ::close(fds[1]);
  daemon->Wait();  // returns only because EOF stopped it after the queue drained
  ::close(fds[0]);
  EXPECT_EQ(Clips().size(), 3u);
  for (const std::string id : {"000001", "000002", "000003"}) EXPECT_EQ(daemon->Job(id)->state, JobState::kDone);
}

TEST_F(DaemonTest, QuitStopsAndShutdownCancelsTheRunningJobWhichResumesNextStart) {
  std::promise<void> started;
  auto daemon = StartDaemon(Options(), [&](const JobContext& context) -> StatusOr<JobOutcome> {
    context.progress("render", 0.0);
    started.set_value();
    // Spin (no sleep) until the daemon asks us to stop, as a pipeline stage would between steps.
    while (context.progress("render", 0.5)) std::this_thread::yield();
    return CancelledError("cancelled at render");
  });
  const std::string id = Call(R"({"cmd":"capture"})")["job"];
  started.get_future().wait();
  EXPECT_EQ(Call(R"({"cmd":"status"})")["processing"]["stage"], "render");
  EXPECT_EQ(Call(R"({"cmd":"quit"})")["ok"], true);
  daemon->Wait();
  EXPECT_FALSE(fs::exists(dir() / "ctl.sock"));
  EXPECT_EQ(daemon->Job(id)->state, JobState::kSaved);
  EXPECT_EQ(daemon->Job(id)->attempts, 0);
  daemon.reset();

  // The next start resumes it, and with exit_when_idle stops once it is done.
  DaemonOptions options = Options();
  options.exit_when_idle = true;
  auto again = StartDaemon(options);
  again->Wait();
  EXPECT_EQ(again->Job(id)->state, JobState::kDone);
  EXPECT_EQ(again->Job(id)->attempts, 1);
  EXPECT_EQ(Clips().size(), 1u);
}

TEST_F(DaemonTest, RecoveryResumesSavedAndInterruptedJobsAndFailsLostCaptures) {
  DaemonOptions options = Options();
  StorageLayout layout(options.storage.root);
  ASSERT_TRUE(layout.Prepare().ok());
  auto journal = JobJournal::Open(layout.JobsDir()).value();
  GradientSource source;
  SourceConfig granted;
  ASSERT_TRUE(source.Configure({}, &granted).ok());
  auto save = [&](const std::string& id, JobState state, int attempts) {
    Recording recording{source.Describe(), source.Next(std::chrono::seconds(1)).value(), "crashed daemon"};
    ASSERT_TRUE(WriteRecording(layout.CaptureDir(id), recording).ok());
    JobRecord record;
    record.id = id;
    record.state = state;
    record.attempts = attempts;
    record.capture_dir = layout.CaptureDir(id).string();
    ASSERT_TRUE(journal->Put(record).ok());
  };
  save("000001", JobState::kSaved, 0);       // saved, never processed
  save("000002", JobState::kProcessing, 1);  // the daemon died while processing
  save("000003", JobState::kCapturing, 0);   // saved but the journal update was lost
  save("000004", JobState::kProcessing, 7);  // the daemon was killed during it seven times: still resumed
  JobRecord lost;                            // pressed, never captured
  lost.id = "000005";
  lost.state = JobState::kCapturing;
  ASSERT_TRUE(journal->Put(lost).ok());
  journal.reset();

  options.exit_when_idle = true;
  auto daemon = StartDaemon(options);
  daemon->Wait();
  EXPECT_EQ(daemon->Job("000001")->state, JobState::kDone);
  EXPECT_EQ(daemon->Job("000002")->state, JobState::kDone);
  EXPECT_EQ(daemon->Job("000002")->attempts, 2);
  EXPECT_EQ(daemon->Job("000003")->state, JobState::kDone);
  EXPECT_EQ(daemon->Job("000004")->state, JobState::kDone);
  EXPECT_EQ(daemon->Job("000004")->worker_crashes, 0);
  EXPECT_EQ(daemon->Job("000005")->state, JobState::kFailed);
  EXPECT_THAT(daemon->Job("000005")->error, HasSubstr("before the capture was saved"));
  EXPECT_EQ(Clips().size(), 4u);
}

TEST_F(DaemonTest, APressOnAFullDiskIsRefusedBeforeItIsAcknowledged) {
  DaemonOptions options = Options();
  options.storage.min_free_bytes = 1ull << 62;  // more than any disk holds
  auto daemon = StartDaemon(options);
  const nlohmann::json reply = Call(R"({"cmd":"capture"})");
  EXPECT_EQ(reply["ok"], false) << reply.dump();
  EXPECT_EQ(reply["code"], "RESOURCE_EXHAUSTED");
  EXPECT_THAT(reply["error"].get<std::string>(),
              ::testing::MatchesRegex("press refused: disk full: [0-9]+ MB free under .*/store, need [0-9]+ MB"));
  EXPECT_FALSE(reply.contains("job"));
  EXPECT_TRUE(Call(R"({"cmd":"list"})")["jobs"].empty()) << "no job was made for the refused press";
  EXPECT_EQ(Call(R"({"cmd":"status"})")["ok"], true);
}

// A clip that could not be written for want of space is not a failed shot: the job waits, saved,
// with the reason, and is processed again once the store has room; the attempt does not count.
TEST_F(DaemonTest, AClipLostToAFullDiskIsMadeOnceThereIsRoomAgain) {
  std::atomic<int> runs{0};
  DaemonOptions options = Options();
  options.space_retry_interval = std::chrono::milliseconds(50);
  auto daemon = StartDaemon(options, [&runs](const JobContext& context) -> StatusOr<JobOutcome> {
    if (runs.fetch_add(1) == 0) {
      return DiskFullError(context.clip_path.parent_path(), 3'000'000, 40'000'000)
          .WithContext("write " + context.clip_path.string());
    }
    return PngJob(context);
  });
  const std::string id = Call(R"({"cmd":"capture"})")["job"];
  nlohmann::json job = Call(R"({"cmd":"wait","job":")" + id + R"("})")["job"];
  EXPECT_EQ(job["state"], "done") << job.dump();
  EXPECT_EQ(runs.load(), 2);
  EXPECT_EQ(job["attempts"], 1) << "the attempt lost to the full disk does not count";
  EXPECT_TRUE(fs::exists(daemon->layout().ClipPath(id)));
}

TEST_F(DaemonTest, StaleSocketFromACrashedDaemonIsReplaced) {
  // A bound socket whose process has gone: the file stays, nobody listens.
  int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  std::snprintf(address.sun_path, sizeof(address.sun_path), "%s", (dir() / "ctl.sock").c_str());
  ASSERT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)), 0);
  ::close(fd);
  ASSERT_TRUE(fs::exists(dir() / "ctl.sock"));
  auto daemon = StartDaemon(Options());
  EXPECT_EQ(Call(R"({"cmd":"status"})")["ok"], true);
}

TEST_F(DaemonTest, SecondDaemonOnTheSameSocketIsRefused) {
  auto daemon = StartDaemon(Options());
  DaemonOptions options = Options();
  options.storage.root = dir() / "other";
  Daemon second(options, std::make_unique<GradientSource>(), PngJob);
  Status status = second.Start();
  EXPECT_EQ(status.code(), StatusCode::kAlreadyExists) << status.ToString();
  EXPECT_EQ(Call(R"({"cmd":"status"})")["ok"], true);
}

// Bytes of every regular file under `dir`.
uint64_t BytesUnder(const fs::path& dir) {
  uint64_t total = 0;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    if (entry.is_regular_file()) total += entry.file_size();
  }
  return total;
}

TEST_F(DaemonTest, FullDiskShowsInStatus) {
  DaemonOptions options = Options();
  options.storage.min_free_bytes = 1ull << 62;
  auto daemon = StartDaemon(options);
  nlohmann::json status = Call(R"({"cmd":"status"})");
  EXPECT_EQ(status["storage"]["full"], true) << status.dump();
  EXPECT_THAT(status["storage"]["reason"].get<std::string>(),
              ::testing::MatchesRegex("RESOURCE_EXHAUSTED: disk full: [0-9]+ MB free under .*/store, need [0-9]+ MB"));
  EXPECT_GT(status["storage"]["free_mb"].get<double>(), 0);
  DaemonOptions roomy = Options();
  daemon.reset();
  daemon = StartDaemon(roomy);
  status = Call(R"({"cmd":"status"})");
  EXPECT_EQ(status["storage"]["full"], false) << status.dump();
  EXPECT_EQ(status["storage"]["reason"], "");
}

TEST_F(DaemonTest, QuotaEvictsTheOldestClipsWithTheirCaptures) {
  // Measure one job's whole footprint (capture, clip, journal record), then allow about three.
  auto first = StartDaemon(Options());
  const std::string one = Call(R"({"cmd":"capture"})")["job"];
  ASSERT_EQ(Call(R"({"cmd":"wait","job":")" + one + R"("})")["job"]["state"], "done");
  const uint64_t job_bytes = BytesUnder(dir() / "store");
  first.reset();

  DaemonOptions options = Options();
  // Room for two jobs and the next one; the records of evicted jobs stay (a few hundred bytes each).
  options.storage.quota_bytes = 3 * job_bytes + 2000;
  auto daemon = StartDaemon(options);
  std::vector<std::string> ids = {one};
  for (int i = 0; i < 6; ++i) {
    ids.push_back(Call(R"({"cmd":"capture"})")["job"]);
    nlohmann::json job = Call(R"({"cmd":"wait","job":")" + ids.back() + R"("})")["job"];
    ASSERT_EQ(job["state"], "done") << job.dump();
    EXPECT_LE(BytesUnder(dir() / "store"), options.storage.quota_bytes + job_bytes / 4) << "after job " << ids.back();
  }
  // The oldest are evicted whole (clip and capture), their records stay and say so; the newest stay.
  size_t kept = 0;
  for (size_t i = 0; i < ids.size(); ++i) {
    const JobRecord record = *daemon->Job(ids[i]);
    EXPECT_EQ(record.state, JobState::kDone);
    const bool has_clip = fs::exists(daemon->layout().ClipPath(ids[i]));
    EXPECT_EQ(has_clip, fs::exists(daemon->layout().CaptureDir(ids[i]))) << ids[i];
    if (has_clip) {
      kept++;
      EXPECT_EQ(record.clip_path, daemon->layout().ClipPath(ids[i]).string());
    } else {
      EXPECT_EQ(kept, 0u) << "evicted " << ids[i] << " after a kept newer clip";
      EXPECT_THAT(record.note, HasSubstr("evicted"));
      EXPECT_THAT(record.note, HasSubstr("storage.quota_mb"));
      EXPECT_TRUE(record.clip_path.empty());
      nlohmann::json fetched = Call(R"({"cmd":"fetch","job":")" + ids[i] + R"("})");
      EXPECT_EQ(fetched["code"], "NOT_FOUND");
      EXPECT_THAT(fetched["error"].get<std::string>(), HasSubstr("its clip is gone: evicted"));
    }
  }
  EXPECT_GE(kept, 2u);
  EXPECT_LE(kept, 3u);
  EXPECT_TRUE(fs::exists(daemon->layout().ClipPath(ids.back())));
  nlohmann::json status = Call(R"({"cmd":"status"})");
  EXPECT_EQ(status["storage"]["full"], false);
  EXPECT_DOUBLE_EQ(status["storage"]["quota_mb"].get<double>(), options.storage.quota_bytes / 1e6);
}

TEST_F(DaemonTest, QuotaNeverEvictsUnprocessedCaptures) {
  // One finished job stays in the store (the newest clip: not evictable yet) and sets the
  // estimate of what the next job will need.
  auto measure = StartDaemon(Options());
  const std::string one = Call(R"({"cmd":"capture"})")["job"];
  ASSERT_EQ(Call(R"({"cmd":"wait","job":")" + one + R"("})")["job"]["state"], "done");
  const uint64_t record_bytes = BytesUnder(measure->layout().JobsDir());
  const uint64_t capture_bytes = BytesUnder(measure->layout().CaptureDir(one)) + record_bytes;
  const uint64_t job_bytes = BytesUnder(dir() / "store");
  measure.reset();

  std::promise<void> release;
  std::shared_future<void> released = release.get_future().share();
  DaemonOptions options = Options();
  // Two unprocessed captures fit beside the done job and the next job's estimate; a third does not.
  options.storage.quota_bytes = 2 * job_bytes + capture_bytes + capture_bytes / 2;
  auto daemon = StartDaemon(options, [&](const JobContext& context) {
    released.wait();  // hold processing: every capture stays unprocessed
    return PngJob(context);
  });
  const std::string a = Call(R"({"cmd":"capture"})")["job"];
  const std::string b = Call(R"({"cmd":"capture"})")["job"];
  const std::string c = Call(R"({"cmd":"capture"})")["job"];
  nlohmann::json refused = Call(R"({"cmd":"wait","job":")" + c + R"("})")["job"];
  EXPECT_EQ(refused["state"], "failed");
  EXPECT_THAT(refused["error"].get<std::string>(),
              ::testing::MatchesRegex("RESOURCE_EXHAUSTED: storage quota: [0-9]+ MB used of [0-9]+ MB under .*/store, "
                                      "the next job needs about [0-9]+ MB; nothing left to evict .*"));
  EXPECT_TRUE(ReadRecording(daemon->layout().CaptureDir(a)).ok());
  EXPECT_TRUE(ReadRecording(daemon->layout().CaptureDir(b)).ok());
  EXPECT_EQ(Call(R"({"cmd":"status"})")["storage"]["evictable_mb"], 0.0);
  release.set_value();
  daemon->WaitUntilIdle();
  EXPECT_EQ(daemon->Job(a)->state, JobState::kDone);
  EXPECT_EQ(daemon->Job(b)->state, JobState::kDone);
  // Now a's clip may go (b's is the newest), and the next press works.
  const std::string d = Call(R"({"cmd":"capture"})")["job"];
  EXPECT_EQ(Call(R"({"cmd":"wait","job":")" + d + R"("})")["job"]["state"], "done");
  EXPECT_FALSE(fs::exists(daemon->layout().CaptureDir(a)));
  EXPECT_TRUE(fs::exists(daemon->layout().ClipPath(b)));
  EXPECT_TRUE(fs::exists(daemon->layout().ClipPath(d)));
}

TEST_F(DaemonTest, FetchGivesPathSizeChecksumAndInlineBytes) {
  auto daemon = StartDaemon(Options());
  const std::string id = Call(R"({"cmd":"capture"})")["job"];
  ASSERT_EQ(Call(R"({"cmd":"wait","job":")" + id + R"("})")["job"]["state"], "done");
  const fs::path clip = daemon->layout().ClipPath(id);
  const std::string bytes = ReadFileToString(clip).value();

  nlohmann::json fetched = Call(R"({"cmd":"fetch","job":")" + id + R"("})");
  ASSERT_EQ(fetched["ok"], true) << fetched.dump();
  EXPECT_EQ(fetched["path"], clip.string());
  EXPECT_EQ(fetched["bytes"], bytes.size());
  EXPECT_EQ(fetched["sha256"], capture::Sha256HexOfText(bytes));
  EXPECT_FALSE(fetched.contains("data"));

  nlohmann::json with_data = Call(R"({"cmd":"fetch","job":")" + id + R"(","inline":true})");
  ASSERT_EQ(with_data["ok"], true);
  // Decode the base64 with OpenSSL-free arithmetic: it must give back the clip's bytes.
  const std::string data = with_data["data"];
  EXPECT_EQ(data.size() % 4, 0u);
  std::string decoded;
  uint32_t acc = 0;
  int bits = 0;
  for (char ch : data) {
    if (ch == '=') break;
    const std::string alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    acc = (acc << 6) | static_cast<uint32_t>(alphabet.find(ch));
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      decoded.push_back(static_cast<char>((acc >> bits) & 0xff));
    }
  }
  EXPECT_EQ(decoded, bytes);
  EXPECT_EQ(Base64Encode("Ma"), "TWE=");
  EXPECT_EQ(Base64Encode("Man"), "TWFu");
  EXPECT_EQ(Base64Encode("M"), "TQ==");

  EXPECT_EQ(Call(R"({"cmd":"fetch","job":"424242"})")["code"], "NOT_FOUND");
  // A clip over the inline limit is refused with its path.
  ASSERT_TRUE(WriteFileAtomically(clip, std::string(kMaxInlineClipBytes + 1, 'x')).ok());
  nlohmann::json too_big = Call(R"({"cmd":"fetch","job":")" + id + R"(","inline":true})");
  EXPECT_EQ(too_big["code"], "OUT_OF_RANGE");
  EXPECT_THAT(too_big["error"].get<std::string>(), HasSubstr("read it from " + clip.string()));
  EXPECT_EQ(Call(R"({"cmd":"fetch","job":")" + id + R"("})")["bytes"], kMaxInlineClipBytes + 1);
}

TEST_F(DaemonTest, FetchOfAJobWithoutClipSaysWhy) {
  auto daemon = StartDaemon(
      Options(), [](const JobContext&) -> StatusOr<JobOutcome> { return DataLossError("depth: no plane found"); });
  const std::string id = Call(R"({"cmd":"capture"})")["job"];
  ASSERT_EQ(Call(R"({"cmd":"wait","job":")" + id + R"("})")["job"]["state"], "failed");
  nlohmann::json fetched = Call(R"({"cmd":"fetch","job":")" + id + R"("})");
  EXPECT_EQ(fetched["code"], "FAILED_PRECONDITION");
  EXPECT_THAT(fetched["error"].get<std::string>(),
              HasSubstr("failed, it has no clip: DATA_LOSS: depth: no plane found"));
}

TEST_F(DaemonTest, SetMoveAppliesToJobsPressedAfterIt) {
  std::mutex moves_mutex;
  std::map<std::string, std::string> moves;
  auto daemon = StartDaemon(Options(), [&](const JobContext& context) {
    std::lock_guard<std::mutex> lock(moves_mutex);
    moves[context.job_id] = context.settings.move;
    return PngJob(context);
  });
  const std::string before = Call(R"({"cmd":"capture"})")["job"];
  nlohmann::json bad = Call(R"({"cmd":"set_move","move":"barrel_roll"})");
  EXPECT_EQ(bad["code"], "INVALID_ARGUMENT");
  EXPECT_THAT(
      bad["error"].get<std::string>(),
      HasSubstr("unknown move \"barrel_roll\", want one of auto, dolly_zoom, morph, pan_zoom_2d, establishing_dolly"));
  EXPECT_EQ(Call(R"({"cmd":"status"})")["move"], nullptr);
  nlohmann::json set = Call(R"({"cmd":"set_move","move":"establishing_dolly"})");
  EXPECT_EQ(set["ok"], true);
  EXPECT_EQ(set["move"], "establishing_dolly");
  const std::string after = Call(R"({"cmd":"capture"})")["job"];
  daemon->WaitUntilIdle();
  EXPECT_EQ(Call(R"({"cmd":"status"})")["move"], "establishing_dolly");
  std::lock_guard<std::mutex> lock(moves_mutex);
  EXPECT_EQ(moves[before], "");  // the config's move
  EXPECT_EQ(moves[after], "establishing_dolly");
  EXPECT_EQ(daemon->Job(after)->move, "establishing_dolly");  // journaled: a resumed job keeps it
}

TEST_F(DaemonTest, SetSettingsAppliesToJobsPressedAfterItAndSurvivesARestart) {
  std::mutex settings_mutex;
  std::map<std::string, PressSettings> settings;
  const JobRunner runner = [&](const JobContext& context) {
    std::lock_guard<std::mutex> lock(settings_mutex);
    settings[context.job_id] = context.settings;
    return PngJob(context);
  };
  std::string before, after;
  {
    auto daemon = StartDaemon(Options(), runner);
    before = Call(R"({"cmd":"capture"})")["job"];
    // A bad field is refused, named, and changes nothing.
    nlohmann::json bad = Call(R"({"cmd":"set_settings","format":"gif","effect":"sepia"})");
    EXPECT_EQ(bad["code"], "INVALID_ARGUMENT");
    EXPECT_THAT(bad["error"].get<std::string>(), HasSubstr("effect: 'sepia' is not one of"));
    EXPECT_EQ(Call(R"({"cmd":"status"})")["settings"]["format"], nullptr);
    EXPECT_EQ(Call(R"({"cmd":"set_settings","fps":60})")["code"], "INVALID_ARGUMENT");

    nlohmann::json set = Call(R"({"cmd":"set_settings","effect":"saturation","format":"gif","size":"1080x1920"})");
    ASSERT_EQ(set["ok"], true) << set.dump();
    EXPECT_EQ(set["settings"]["format"], "gif");
    EXPECT_EQ(Call(R"({"cmd":"set_move","move":"dolly_in"})")["ok"], true);  // set_move is one field of them
    after = Call(R"({"cmd":"capture"})")["job"];
    daemon->WaitUntilIdle();
    EXPECT_EQ(daemon->Job(after)->format, "gif");  // journaled: a resumed job keeps them
    EXPECT_EQ(daemon->Job(after)->size, "1080x1920");
  }
  {
    std::lock_guard<std::mutex> lock(settings_mutex);
    EXPECT_TRUE(settings[before].Empty());  // the config's
    EXPECT_EQ(settings[after].move, "dolly_in");
    EXPECT_EQ(settings[after].effect, "saturation");
    EXPECT_EQ(settings[after].format, "gif");
    EXPECT_EQ(settings[after].size, "1080x1920");
  }
  // A restart keeps them; null puts a field back to the config's.
  auto daemon = StartDaemon(Options(), runner);
  nlohmann::json status = Call(R"({"cmd":"status"})");
  EXPECT_EQ(status["settings"],
            nlohmann::json({{"move", "dolly_in"}, {"effect", "saturation"}, {"format", "gif"}, {"size", "1080x1920"}}));
  EXPECT_EQ(Call(R"({"cmd":"set_settings","format":null})")["settings"]["format"], nullptr);
  const std::string third = Call(R"({"cmd":"capture"})")["job"];
  daemon->WaitUntilIdle();
  std::lock_guard<std::mutex> lock(settings_mutex);
  EXPECT_EQ(settings[third].format, "");
  EXPECT_EQ(settings[third].size, "1080x1920");
}

TEST_F(DaemonTest, SetShotAppliesToJobsPressedAfterItAndErrorsNameTheField) {
  std::mutex shots_mutex;
  std::map<std::string, std::string> shots;
  auto daemon = StartDaemon(Options(), [&](const JobContext& context) {
    std::lock_guard<std::mutex> lock(shots_mutex);
    shots[context.job_id] = context.shot;
    return PngJob(context);
  });
  const std::string before = Call(R"({"cmd":"capture"})")["job"];
  // A bad shot is refused, naming the field and the value, and changes nothing.
  nlohmann::json bad =
      Call(R"({"cmd":"set_shot","shot":{"segments":[{"keyframes":[{"t":0,"position_m":[0,0,0],"look_at_m":[0,0,1],)"
           R"("focal_px":"wide"},{"t":1,"position_m":[0.02,0,0],"look_at_m":[0,0,1]}]}]}})");
  EXPECT_EQ(bad["code"], "INVALID_ARGUMENT");
  EXPECT_THAT(bad["error"].get<std::string>(), HasSubstr("shot.segments[0].keyframes[0].focal_px"));
  nlohmann::json not_object = Call(R"({"cmd":"set_shot","shot":"dolly.json"})");
  EXPECT_EQ(not_object["code"], "INVALID_ARGUMENT");
  EXPECT_THAT(not_object["error"].get<std::string>(), HasSubstr("shot: want an object or null, got string"));
  nlohmann::json unknown_move = Call(R"({"cmd":"set_shot","shot":{"segments":[{"move":"barrel_roll"}]}})");
  EXPECT_EQ(unknown_move["code"], "INVALID_ARGUMENT");
  EXPECT_THAT(unknown_move["error"].get<std::string>(), HasSubstr("barrel_roll"));
  EXPECT_EQ(Call(R"({"cmd":"status"})")["shot"], nullptr);

  const std::string shot_text = R"({"duration_s":2,"segments":[{"move":"dolly_in","effect":"none"},{"keyframes":[)"
                                R"({"t":0,"position_m":[0,0,0],"look_at_m":[0,0,1.5],"focal_scale":1},)"
                                R"({"t":1,"position_m":[0.02,0,-0.05],"look_at_m":[0,0,1.5],"focal_scale":1.2}]}]})";
  nlohmann::json set = Call(R"({"cmd":"set_shot","shot":)" + shot_text + "}");
  EXPECT_EQ(set["ok"], true) << set.dump();
  EXPECT_EQ(set["segments"], 2);
  const std::string after = Call(R"({"cmd":"capture"})")["job"];
  daemon->WaitUntilIdle();
  EXPECT_EQ(Call(R"({"cmd":"status"})")["shot"]["segments"].size(), 2u);
  EXPECT_EQ(Call(R"({"cmd":"set_shot","shot":null})")["shot"], nullptr);  // back to the move
  const std::string cleared = Call(R"({"cmd":"capture"})")["job"];
  daemon->WaitUntilIdle();
  std::lock_guard<std::mutex> lock(shots_mutex);
  EXPECT_EQ(shots[before], "");
  ASSERT_FALSE(shots[after].empty());
  EXPECT_EQ(nlohmann::json::parse(shots[after]), nlohmann::json::parse(shot_text));
  EXPECT_EQ(daemon->Job(after)->shot, shots[after]);  // journaled: a resumed job keeps it
  EXPECT_EQ(shots[cleared], "");
}

TEST_F(DaemonTest, CancelStopsAQueuedJobOrTheRunningClipAndKeepsTheCapture) {
  std::promise<void> started;
  std::atomic<int> runs{0};
  auto daemon = StartDaemon(Options(), [&](const JobContext& context) -> StatusOr<JobOutcome> {
    if (runs++ == 0) {
      context.progress("render", 0.0);
      started.set_value();
      while (context.progress("render", 0.5)) std::this_thread::yield();
      return CancelledError("pipeline cancelled during render");
    }
    return PngJob(context);
  });
  const std::string running = Call(R"({"cmd":"capture"})")["job"];
  started.get_future().wait();
  const std::string queued = Call(R"({"cmd":"capture"})")["job"];
  const std::string third = Call(R"({"cmd":"capture"})")["job"];
  // Wait until the second is saved (queued for processing) before cancelling it.
  for (int i = 0; i < 1000 && daemon->Job(third)->state != JobState::kSaved; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_EQ(daemon->Job(queued)->state, JobState::kSaved);
  nlohmann::json cancelled = Call(R"({"cmd":"cancel","job":")" + queued + R"("})");
  EXPECT_EQ(cancelled["ok"], true) << cancelled.dump();
  EXPECT_EQ(cancelled["was"], "saved");
  nlohmann::json job = Call(R"({"cmd":"wait","job":")" + queued + R"("})")["job"];
  EXPECT_EQ(job["state"], "failed");
  EXPECT_THAT(job["error"].get<std::string>(), HasSubstr("CANCELLED: cancelled by request before processing"));
  EXPECT_TRUE(ReadRecording(daemon->layout().CaptureDir(queued)).ok());

  EXPECT_EQ(Call(R"({"cmd":"cancel","job":")" + running + R"("})")["was"], "processing");
  job = Call(R"({"cmd":"wait","job":")" + running + R"("})")["job"];
  EXPECT_EQ(job["state"], "failed");
  EXPECT_THAT(job["error"].get<std::string>(),
              HasSubstr("CANCELLED: cancelled by request during render; raw capture kept"));
  EXPECT_TRUE(ReadRecording(daemon->layout().CaptureDir(running)).ok());
  EXPECT_FALSE(fs::exists(daemon->layout().ClipPath(running)));

  // The third goes on; cancelling finished or unknown jobs is refused.
  EXPECT_EQ(Call(R"({"cmd":"wait","job":")" + third + R"("})")["job"]["state"], "done");
  EXPECT_EQ(Call(R"({"cmd":"cancel","job":")" + third + R"("})")["code"], "FAILED_PRECONDITION");
  EXPECT_EQ(Call(R"({"cmd":"cancel","job":"777777"})")["code"], "NOT_FOUND");
  EXPECT_EQ(Call(R"({"cmd":"status"})")["jobs"]["failed"], 2);
}

TEST_F(DaemonTest, CancelAJobStillWaitingForTheCamera) {
  auto daemon = StartDaemon(Options());
  source_->hold = true;  // the camera takes its time with the first capture
  const std::string first = Call(R"({"cmd":"capture"})")["job"];
  while (Call(R"({"cmd":"status"})")["capturing"] != first) std::this_thread::sleep_for(std::chrono::milliseconds(2));
  const std::string second = Call(R"({"cmd":"capture"})")["job"];
  nlohmann::json busy = Call(R"({"cmd":"cancel","job":")" + first + R"("})");
  EXPECT_EQ(busy["code"], "FAILED_PRECONDITION");
  EXPECT_THAT(busy["error"].get<std::string>(), HasSubstr("is being captured right now"));
  nlohmann::json cancelled = Call(R"({"cmd":"cancel","job":")" + second + R"("})");
  EXPECT_EQ(cancelled["ok"], true) << cancelled.dump();
  EXPECT_EQ(cancelled["was"], "capturing");
  source_->hold = false;
  daemon->WaitUntilIdle();
  EXPECT_EQ(daemon->Job(first)->state, JobState::kDone);
  EXPECT_EQ(daemon->Job(second)->state, JobState::kFailed);
  EXPECT_THAT(daemon->Job(second)->error, HasSubstr("CANCELLED: cancelled by request before the capture"));
  EXPECT_FALSE(fs::exists(daemon->layout().CaptureDir(second)));
  EXPECT_EQ(source_->count, 1u);  // the camera was asked once
}

}  // namespace
}  // namespace px::device
