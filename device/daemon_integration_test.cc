// The daemon with the real simulated camera, pipeline and encoder: a press through the control
// socket -> a valid recording under captures/ -> a clip under clips/ -> status shows done.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "capture/recording.h"
#include "device/control/control_client.h"
#include "device/daemon_factory.h"
#include "device/small_daemon_config.h"
#include "pipeline/direct/camera_path.h"
#include "tests/testing/animation_probe.h"
#include "tests/testing/temp_dir.h"
#include "tests/testing/video_probe.h"

namespace px::device {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

using DaemonIntegrationTest = px::testing::TempDirTest;

nlohmann::json Call(ControlClient& client,
                    const std::string& request,
                    std::chrono::milliseconds timeout = std::chrono::seconds(10)) {
  auto reply = client.Call(request, timeout);
  EXPECT_TRUE(reply.ok()) << reply.status().ToString();
  return reply.ok() ? nlohmann::json::parse(*reply) : nlohmann::json(nullptr);
}

// A started daemon after one press through its socket, with the job waited for and the clips it
// announced.
struct PressedDaemon {
  std::unique_ptr<Daemon> daemon;
  std::unique_ptr<ControlClient> client;
  std::string id;
  nlohmann::json waited;
  std::shared_ptr<std::mutex> announced_mutex = std::make_shared<std::mutex>();
  std::shared_ptr<std::vector<fs::path>> announced = std::make_shared<std::vector<fs::path>>();

  std::vector<fs::path> Announced() const {
    std::lock_guard<std::mutex> lock(*announced_mutex);
    return *announced;
  }
};

void PressAndWait(const DaemonConfig& config, PressedDaemon* out) {
  auto daemon = BuildDaemon(config, BuiltWorkerFlags());
  ASSERT_TRUE(daemon.ok()) << daemon.status().ToString();
  out->daemon = std::move(daemon).value();
  out->daemon->SetClipListener([mutex = out->announced_mutex, announced = out->announced](const fs::path& clip) {
    std::lock_guard<std::mutex> lock(*mutex);
    announced->push_back(clip);
  });
  ASSERT_TRUE(out->daemon->Start().ok());
  out->client = ControlClient::Connect(config.control_socket).value();
  nlohmann::json pressed = Call(*out->client, R"({"cmd":"capture"})");
  ASSERT_EQ(pressed["ok"], true) << pressed.dump();
  out->id = pressed["job"];
  // Generous: the whole job takes about a second here, but CI machines are shared.
  out->waited = Call(*out->client, R"({"cmd":"wait","job":")" + out->id + R"("})", std::chrono::minutes(5));
  ASSERT_EQ(out->waited["ok"], true) << out->waited.dump();
  ASSERT_EQ(out->waited["job"]["state"], "done") << out->waited.dump();
}

TEST_F(DaemonIntegrationTest, PressThroughSocketGivesRecordingThenClip) {
  const DaemonConfig config = SmallDaemonConfig(dir());
  PressedDaemon run;
  ASSERT_NO_FATAL_FAILURE(PressAndWait(config, &run));
  const std::string& id = run.id;
  auto& client = run.client;
  auto& daemon = run.daemon;

  const StorageLayout& layout = daemon->layout();
  auto recording = ReadRecording(layout.CaptureDir(id));
  ASSERT_TRUE(recording.ok()) << recording.status().ToString();
  ASSERT_TRUE(recording->source.rig.has_value());
  EXPECT_EQ(recording->source.rig->NumViews(), 9);
  EXPECT_EQ(recording->frames.frames.size(), 1u);
  EXPECT_THAT(recording->created_by, HasSubstr("parallaxd"));

  const fs::path clip = layout.ClipPath(id);
  auto video = px::testing::ProbeVideo(clip);
  ASSERT_TRUE(video.ok()) << clip << ": " << video.status().ToString();
  EXPECT_EQ(video->codec, "h264");
  EXPECT_EQ(video->frames_decoded, NumFrames(10, 0.5));
  EXPECT_TRUE(fs::exists(ClipReportPathFor(clip)));
  EXPECT_EQ(run.Announced(), std::vector<fs::path>{clip});

  nlohmann::json status = Call(*client, R"({"cmd":"status"})");
  EXPECT_EQ(status["state"], "idle");
  EXPECT_EQ(status["jobs"]["done"], 1);
  EXPECT_EQ(status["last_job"]["id"], id);
  EXPECT_EQ(status["last_job"]["state"], "done");
  EXPECT_EQ(status["last_job"]["clip_path"], clip.string());
  EXPECT_THAT(status["last_job"]["note"].get<std::string>(), HasSubstr("9 views"));

  EXPECT_EQ(Call(*client, R"({"cmd":"quit"})")["ok"], true);
  daemon->Wait();
  EXPECT_FALSE(fs::exists(config.control_socket));
}

// clip.format gif: the clip is clips/<id>.gif, announced and journalled under that name, found by
// the storage accounting, and a fetch returns its bytes.
TEST_F(DaemonIntegrationTest, ConfiguredClipFormatNamesTheClip) {
  DaemonConfig config = SmallDaemonConfig(dir());
  config.clip.format = "gif";
  PressedDaemon run;
  ASSERT_NO_FATAL_FAILURE(PressAndWait(config, &run));
  const std::string& id = run.id;
  auto& client = run.client;
  auto& daemon = run.daemon;
  const nlohmann::json& waited = run.waited;

  const StorageLayout& layout = daemon->layout();
  const fs::path clip = layout.ClipsDir() / (id + ".gif");
  EXPECT_EQ(layout.FindClip(id), clip);
  EXPECT_FALSE(fs::exists(layout.ClipPath(id))) << "no MP4 beside the GIF";
  auto animation = px::testing::ProbeAnimation(clip);
  ASSERT_TRUE(animation.ok()) << animation.status().ToString();
  EXPECT_EQ(animation->frames, NumFrames(10, 0.5));
  EXPECT_EQ(animation->plays, 0);
  EXPECT_TRUE(fs::exists(ClipReportPathFor(clip)));
  EXPECT_EQ(waited["job"]["clip_path"], clip.string());
  EXPECT_EQ(run.Announced(), std::vector<fs::path>{clip});
  nlohmann::json fetched = Call(*client, R"({"cmd":"fetch","job":")" + id + R"("})");
  EXPECT_EQ(fetched["ok"], true) << fetched.dump();
  EXPECT_EQ(fetched["bytes"], fs::file_size(clip));

  EXPECT_EQ(Call(*client, R"({"cmd":"quit"})")["ok"], true);
  daemon->Wait();
}

TEST_F(DaemonIntegrationTest, MissingSceneFileIsAnErrorNamingTheField) {
  DaemonConfig config = SmallDaemonConfig(dir());
  config.source.sim.scene = dir() / "no_such_scene.json";
  auto daemon = BuildDaemon(config, BuiltWorkerFlags());
  ASSERT_FALSE(daemon.ok());
  EXPECT_THAT(daemon.status().message(), HasSubstr("source.sim"));
  EXPECT_THAT(daemon.status().message(), HasSubstr("no_such_scene.json"));
}

TEST_F(DaemonIntegrationTest, UnknownMoveIsAnErrorNamingTheField) {
  DaemonConfig config = SmallDaemonConfig(dir());
  config.clip.move = "barrel_roll";
  auto daemon = BuildDaemon(config, BuiltWorkerFlags());
  EXPECT_EQ(daemon.status().message(), "clip.move: 'barrel_roll' is not a known camera move");
}

}  // namespace
}  // namespace px::device
