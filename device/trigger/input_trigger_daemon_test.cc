// The trigger inside the real daemon: input_event records written into a FIFO that stands in for
// /dev/input/event0 become jobs through the daemon's poll loop, next to presses on the control
// socket, and the daemon stays up while the device vanishes and comes back.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <thread>

#include "device/control/control_client.h"
#include "device/daemon.h"
#include "device/trigger/input_trigger.h"
#include "device/trigger/input_trigger_test_util.h"
#include "pipeline/io/durable_file.h"
#include "tests/testing/temp_dir.h"

namespace px::device {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using testing::Concat;
using testing::EventWriter;
using testing::Key;

// A 32x24 gray sensor: enough for a recording; the clip job below only needs a saved capture.
class TinySource final : public FrameSource {
 public:
  std::string_view Name() const override { return "tiny"; }
  SourceDescription Describe() const override { return {"test:tiny", FrameSetKind::kLatticeFrame, std::nullopt}; }
  StatusOr<ConfigureResult> Configure(const SourceConfig& wanted, SourceConfig* granted) override {
    *granted = {PixelFormat::kGray8, 32, 24, 1};
    return wanted == *granted ? ConfigureResult::kValid : ConfigureResult::kAdjusted;
  }
  StatusOr<FrameSet> Next(std::chrono::milliseconds) override {
    FrameSet set;
    set.capture_id = ++count_;
    Frame frame;
    frame.image = {PixelFormat::kGray8, 32, 24, std::vector<uint8_t>(32 * 24, static_cast<uint8_t>(count_))};
    frame.sequence = count_;
    frame.timestamp_ns = static_cast<int64_t>(count_) * 1'000'000;
    set.frames.push_back(std::move(frame));
    return set;
  }
  void Stop() override {}

 private:
  uint64_t count_ = 0;
};

// A real job: the clip is a text file naming the capture it came from.
StatusOr<JobOutcome> NoteJob(const JobContext& context) {
  PX_RETURN_IF_ERROR(WriteFileAtomically(context.clip_path, context.capture_dir.string() + "\n"));
  return JobOutcome{"note"};
}

class InputTriggerDaemonTest : public px::testing::TempDirTest {
 protected:
  void SetUp() override {
    fifo_ = dir() / "event0";
    ASSERT_EQ(::mkfifo(fifo_.c_str(), 0600), 0);
    InputTriggerOptions trigger;
    trigger.device = fifo_;
    trigger.key_code = KEY_CAMERA;
    trigger.debounce = 50ms;
    trigger.retry = 50ms;
    DaemonOptions options;
    options.storage.root = dir() / "store";
    options.storage.min_free_bytes = 0;
    options.control_socket = dir() / "ctl.sock";
    options.wanted_source = SourceConfig{PixelFormat::kGray8, 32, 24, 1};
    options.loop_inputs.push_back(std::make_shared<InputTrigger>(trigger));
    daemon_ = std::make_unique<Daemon>(std::move(options), std::make_unique<TinySource>(), NoteJob);
    Status started = daemon_->Start();
    ASSERT_TRUE(started.ok()) << started.ToString();
  }
  void TearDown() override {
    if (daemon_) {
      daemon_->RequestStop(true);
      daemon_->Wait();
    }
  }

  nlohmann::json Call(const std::string& request) {
    auto client = ControlClient::Connect(dir() / "ctl.sock");
    EXPECT_TRUE(client.ok()) << client.status().ToString();
    if (!client.ok()) return nullptr;
    auto reply = (*client)->Call(request);
    EXPECT_TRUE(reply.ok()) << reply.status().ToString();
    return reply.ok() ? nlohmann::json::parse(*reply) : nlohmann::json(nullptr);
  }
  size_t NumJobs() { return daemon_->ListJson()["jobs"].size(); }
  // Waits until there are `n` jobs, then a little longer to see that no more come.
  void ExpectJobs(size_t n) {
    const auto end = std::chrono::steady_clock::now() + 10s;
    while (NumJobs() < n && std::chrono::steady_clock::now() < end) std::this_thread::sleep_for(10ms);
    std::this_thread::sleep_for(300ms);
    EXPECT_EQ(NumJobs(), n);
  }

  fs::path fifo_;
  std::unique_ptr<Daemon> daemon_;
};

TEST_F(InputTriggerDaemonTest, ExactlyThePressesBecomeJobsLikeSocketCaptures) {
  EventWriter writer(EventWriter::OpenWhenRead(fifo_, 5000ms));
  ASSERT_TRUE(writer.ok()) << "the daemon never opened the trigger device";
  // One press with autorepeat, a bounce, another key, a release: one job.
  ASSERT_TRUE(writer.Write(Concat({Key(KEY_CAMERA, 1, 1000),
                                   Key(KEY_CAMERA, 0, 1003),
                                   Key(KEY_CAMERA, 1, 1010),
                                   Key(KEY_CAMERA, 2, 1260),
                                   Key(KEY_CAMERA, 2, 1293),
                                   Key(KEY_CAMERA, 0, 1300),
                                   Key(KEY_ENTER, 1, 1400),
                                   Key(KEY_ENTER, 0, 1450)})));
  ExpectJobs(1);
  // A capture on the socket is the same kind of job.
  nlohmann::json reply = Call(R"({"cmd":"capture"})");
  ASSERT_EQ(reply["ok"], true) << reply.dump();
  ExpectJobs(2);
  // Two separate presses: two jobs.
  ASSERT_TRUE(writer.Write(Concat(
      {Key(KEY_CAMERA, 1, 3000), Key(KEY_CAMERA, 0, 3080), Key(KEY_CAMERA, 1, 3400), Key(KEY_CAMERA, 0, 3480)})));
  ExpectJobs(4);
  daemon_->WaitUntilIdle();
  nlohmann::json jobs = daemon_->ListJson()["jobs"];
  ASSERT_EQ(jobs.size(), 4u);
  for (const auto& job : jobs) {
    EXPECT_EQ(job["state"], "done") << job.dump();
    EXPECT_TRUE(fs::exists(job["clip_path"].get<std::string>())) << job.dump();
  }
}

TEST_F(InputTriggerDaemonTest, TheDaemonOutlivesTheDeviceAndTakesItBack) {
  {
    EventWriter writer(EventWriter::OpenWhenRead(fifo_, 5000ms));
    ASSERT_TRUE(writer.ok());
    ASSERT_TRUE(writer.Write(Key(KEY_CAMERA, 1, 1000)));
    ExpectJobs(1);
  }                                                    // the device vanishes (end of file)
  fs::remove(fifo_);                                   // and its node with it
  std::this_thread::sleep_for(200ms);                  // several failed reopens
  EXPECT_EQ(Call(R"({"cmd":"status"})")["ok"], true);  // still serving
  ASSERT_EQ(::mkfifo(fifo_.c_str(), 0600), 0);         // plugged in again
  EventWriter writer(EventWriter::OpenWhenRead(fifo_, 5000ms));
  ASSERT_TRUE(writer.ok()) << "the daemon did not reopen the trigger device";
  ASSERT_TRUE(writer.Write(Key(KEY_CAMERA, 1, 60000)));
  ExpectJobs(2);
}

}  // namespace
}  // namespace px::device
