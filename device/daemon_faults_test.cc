// The real daemon (in process, through its control socket) with the simulated Pop9 camera and
// the real pipeline, driven through every fault sim/faults offers, one press each, on one
// running daemon (source.faults fires each fault at its own capture). For each press: the job's
// error or note names the problem, the raw capture is saved whenever a frame set arrived (even a
// bad one), the daemon answers status, and the next press works; where the pipeline can honestly
// still make a clip (a blank tile, a silently garbled frame), the clip exists and its report
// says what was lost. The image-set faults (an image dropped, images reordered) run on a
// replayed hand-held image set: the capture is saved as it came, and the job's clip is made
// from the images that arrived, with warnings.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "capture/recording.h"
#include "device/control/control_client.h"
#include "device/daemon_factory.h"
#include "pipeline/io/durable_file.h"
#include "tests/testing/temp_dir.h"
#include "tests/testing/video_probe.h"

namespace px::device {
namespace {

// Jobs run in worker processes of the built parallaxd (this test binary serves no --job-worker).
DaemonRunFlags WorkerFlags() {
  DaemonRunFlags flags;
  flags.worker_binary = std::filesystem::path(PX_BINARY_DIR) / "parallaxd";
  return flags;
}

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using ::testing::AllOf;
using ::testing::HasSubstr;

// One press, what happened to it, and what the test expects.
struct Outcome {
  std::string id;
  nlohmann::json job;     // the journal record from "wait"
  nlohmann::json status;  // "status" right after
};

class DaemonFaultsTest : public px::testing::TempDirTest {
 protected:
  DaemonConfig SmallConfig(const std::string& faults_json) {
    DaemonConfig config;
    config.storage.root = dir() / "store";
    config.storage.min_free_bytes = 0;
    config.control_socket = dir() / "ctl.sock";
    config.source.sim.tile_width = 160;
    config.source.sim.tile_height = 120;
    config.source.timeout_ms = 500;  // a stall is noticed quickly
    config.source.faults = FaultSpecsFromJson(nlohmann::json::parse(faults_json), "source.faults").value();
    config.clip.duration_s = 0.3;
    config.clip.fps = 10;
    config.clip.preset = "ultrafast";
    config.clip.num_threads = 2;
    return config;
  }

  void Start(const DaemonConfig& config) {
    auto daemon = BuildDaemon(config, WorkerFlags());
    ASSERT_TRUE(daemon.ok()) << daemon.status().ToString();
    daemon_ = std::move(daemon).value();
    ASSERT_TRUE(daemon_->Start().ok());
    auto client = ControlClient::Connect(config.control_socket);
    ASSERT_TRUE(client.ok()) << client.status().ToString();
    client_ = std::move(client).value();
  }

  nlohmann::json Call(const std::string& request, std::chrono::milliseconds timeout = 10s) {
    auto reply = client_->Call(request, timeout);
    EXPECT_TRUE(reply.ok()) << request << ": " << reply.status().ToString();
    return reply.ok() ? nlohmann::json::parse(*reply) : nlohmann::json::object();
  }

  Outcome PressAndWait() {
    Outcome outcome;
    const nlohmann::json pressed = Call(R"({"cmd":"capture"})");
    EXPECT_EQ(pressed["ok"], true) << pressed.dump();
    outcome.id = pressed.value("job", "");
    const nlohmann::json waited = Call(R"({"cmd":"wait","job":")" + outcome.id + R"("})", 180s);
    EXPECT_EQ(waited["ok"], true) << waited.dump();
    outcome.job = waited.value("job", nlohmann::json::object());
    outcome.status = Call(R"({"cmd":"status"})");
    EXPECT_EQ(outcome.status["ok"], true) << "the daemon must answer status after job " << outcome.id;
    return outcome;
  }

  // The raw capture is a valid recording (frames checked against their hashes, bad ones marked).
  void ExpectCaptureSaved(const Outcome& outcome) {
    auto recording = ReadRecording(daemon_->layout().CaptureDir(outcome.id));
    EXPECT_TRUE(recording.ok()) << "job " << outcome.id << ": " << recording.status().ToString();
  }
  void ExpectClip(const Outcome& outcome) {
    EXPECT_EQ(outcome.job.value("state", ""), "done") << outcome.job.dump();
    auto video = px::testing::ProbeVideo(daemon_->layout().ClipPath(outcome.id));
    EXPECT_TRUE(video.ok()) << "job " << outcome.id << ": " << video.status().ToString();
  }
  std::string Report(const Outcome& outcome) {
    auto text = ReadFileToString(ClipReportPathFor(daemon_->layout().ClipPath(outcome.id)));
    return text.ok() ? *text : "";
  }

  void Stop() {
    EXPECT_EQ(Call(R"({"cmd":"quit"})")["ok"], true);
    daemon_->Wait();
  }

  std::unique_ptr<Daemon> daemon_;
  std::unique_ptr<ControlClient> client_;
};

TEST_F(DaemonFaultsTest, LatticeCameraFaultsOneAfterAnother) {
  Start(SmallConfig(R"([
    {"kind": "truncate", "capture": 1, "keep": 0.6},
    {"kind": "garble", "capture": 2, "bytes": 64, "flagged": true},
    {"kind": "garble", "capture": 3, "bytes": 64, "flagged": false},
    {"kind": "drop", "capture": 4, "view": 4},
    {"kind": "reformat", "capture": 5, "pixel_format": "BGR888", "width": 320, "height": 240},
    {"kind": "stall", "capture": 6},
    {"kind": "vanish", "capture": 7}
  ])"));
  if (HasFatalFailure()) return;
  std::vector<Outcome> outcomes;
  for (int press = 1; press <= 8; ++press) outcomes.push_back(PressAndWait());

  auto job = [&](int press) { return outcomes[press - 1].job; };
  // 1 truncate: the frame arrives short. It is saved as it came; the complete tiles (the first
  // three views) still make a clip, and its report names each lost view.
  ExpectCaptureSaved(outcomes[0]);
  ExpectClip(outcomes[0]);
  EXPECT_THAT(job(1).value("note", ""), HasSubstr("3 views, 0.01 MB, with warnings"));
  EXPECT_THAT(Report(outcomes[0]),
              AllOf(HasSubstr("is truncated (415180 of 691968 bytes)"),
                    HasSubstr("view 8 was lost: its tile (rows 288..407) lies past")));
  // 2 garble the driver flagged: saved, then failed naming the damaged frame.
  ExpectCaptureSaved(outcomes[1]);
  EXPECT_EQ(job(2).value("state", ""), "failed");
  EXPECT_THAT(job(2).value("error", ""),
              AllOf(HasSubstr("DATA_LOSS: capture 2 frame 0"), HasSubstr("the driver flagged the buffer as damaged")));
  // 3 silent garble: the camera cannot tell and neither can the pipeline; the clip is made.
  ExpectCaptureSaved(outcomes[2]);
  ExpectClip(outcomes[2]);
  // 4 drop: a dead lens (blank tile). The other eight views make the clip; the report says so.
  ExpectCaptureSaved(outcomes[3]);
  ExpectClip(outcomes[3]);
  EXPECT_THAT(job(4).value("note", ""), HasSubstr("8 views"));
  EXPECT_THAT(Report(outcomes[3]), HasSubstr("view 4 is blank (grey mean 12.0, stddev 0.00): lens covered or dead"));
  // 5 wrong format and size: saved as delivered, failed naming what came and what was wanted.
  ExpectCaptureSaved(outcomes[4]);
  EXPECT_EQ(job(5).value("state", ""), "failed");
  EXPECT_THAT(job(5).value("error", ""), HasSubstr("wrong_format: got 320x240 BGR888, want 544x424 RGB888"));
  // 6 stall past source.timeout_ms: nothing arrived, nothing to save; the error says how long.
  EXPECT_EQ(job(6).value("state", ""), "failed");
  EXPECT_THAT(job(6).value("error", ""),
              HasSubstr("DEADLINE_EXCEEDED: source sim:sim-pop9-160x120: no frame set within 500 ms"));
  EXPECT_FALSE(fs::exists(daemon_->layout().CaptureDir(outcomes[5].id)));
  // 7 the camera vanishes mid-capture.
  EXPECT_EQ(job(7).value("state", ""), "failed");
  EXPECT_THAT(job(7).value("error", ""),
              HasSubstr("UNAVAILABLE: source sim:sim-pop9-160x120: camera disconnected during capture 7"));
  // 8: the camera is configured again and the next press works.
  ExpectClip(outcomes[7]);
  // The daemon stayed up and counted every job.
  const nlohmann::json status = Call(R"({"cmd":"status"})");
  EXPECT_EQ(status["jobs"]["done"], 4) << status.dump();
  EXPECT_EQ(status["jobs"]["failed"], 4) << status.dump();
  Stop();
}

// Five 32x24 BGR images, a hand-held shot as a PTP tether delivers it.
Recording ImageSetRecording() {
  Recording recording;
  recording.source = {"test:handheld", FrameSetKind::kImageSet, std::nullopt};
  recording.frames.kind = FrameSetKind::kImageSet;
  recording.frames.capture_id = 1;
  for (int k = 0; k < 5; ++k) {
    cv::Mat bgr(24, 32, CV_8UC3, cv::Scalar(40 * k, 7 * k, 200 - 30 * k));
    Frame frame;
    frame.image = FromBgr(bgr, PixelFormat::kBgr888).value();
    frame.sequence = static_cast<uint64_t>(k);
    recording.frames.frames.push_back(std::move(frame));
  }
  recording.created_by = "daemon_faults_test";
  return recording;
}

TEST_F(DaemonFaultsTest, ImageSetFaultsKeepTheCaptureAsItCame) {
  ASSERT_TRUE(WriteRecording(dir() / "handheld", ImageSetRecording()).ok());
  DaemonConfig config = SmallConfig(R"([
    {"kind": "drop", "capture": 1, "view": 2},
    {"kind": "reorder", "capture": 2, "seed": 7}
  ])");
  config.source.kind = "replay";
  config.source.replay.path = dir() / "handheld";
  Start(config);
  if (HasFatalFailure()) return;
  std::vector<Outcome> outcomes;
  for (int press = 1; press <= 3; ++press) outcomes.push_back(PressAndWait());
  for (const Outcome& outcome : outcomes) {
    ExpectCaptureSaved(outcome);
    // Flat colour cards cannot be reconstructed: the button still gives a clip (a morph or a pan
    // and zoom), with warnings that say why.
    EXPECT_EQ(outcome.job.value("state", ""), "done") << outcome.job.dump();
    EXPECT_THAT(outcome.job.value("note", ""), HasSubstr("with warnings"));
  }
  // 1: image 2 never arrived; the recording says so.
  auto dropped = ReadRecording(daemon_->layout().CaptureDir(outcomes[0].id));
  ASSERT_TRUE(dropped.ok());
  EXPECT_EQ(dropped->frames.frames.at(2).status, FrameStatus::kDropped);
  EXPECT_THAT(outcomes[0].job.value("note", ""), HasSubstr("4 views"));
  // 2: the images arrived out of order, each with its own sequence number, as recorded.
  auto reordered = ReadRecording(daemon_->layout().CaptureDir(outcomes[1].id));
  ASSERT_TRUE(reordered.ok());
  std::vector<uint64_t> sequences;
  for (const Frame& frame : reordered->frames.frames) sequences.push_back(frame.sequence);
  EXPECT_NE(sequences, (std::vector<uint64_t>{0, 1, 2, 3, 4}));
  EXPECT_TRUE(std::is_permutation(sequences.begin(), sequences.end(), std::vector<uint64_t>{0, 1, 2, 3, 4}.begin()));
  Stop();
}

}  // namespace
}  // namespace px::device
