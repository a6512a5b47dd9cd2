// The daemon with the real simulated camera, pipeline and encoder: a press through the control
// socket -> a valid recording under captures/ -> a clip under clips/ -> status shows done.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "device/control/control_client.h"
#include "device/daemon_factory.h"
#include "tests/testing/video_probe.h"
#include "tests/testing/temp_dir.h"
#include "pipeline/direct/camera_path.h"
#include "sim/replay/recording.h"

namespace px::device {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

using DaemonIntegrationTest = px::testing::TempDirTest;

// A 3x3 lattice of 160x120 tiles and a 0.5 s clip at 10 fps: the whole job takes seconds.
DaemonConfig SmallConfig(const fs::path& dir) {
  DaemonConfig config;
  config.storage.root = dir / "store";
  config.storage.min_free_bytes = 1'000'000;
  config.control_socket = dir / "ctl.sock";
  config.source.sim.tile_width = 160;
  config.source.sim.tile_height = 120;
  config.clip.duration_s = 0.5;
  config.clip.fps = 10;
  config.clip.preset = "ultrafast";
  return config;
}

nlohmann::json Call(ControlClient& client,
                    const std::string& request,
                    std::chrono::milliseconds timeout = std::chrono::seconds(10)) {
  auto reply = client.Call(request, timeout);
  EXPECT_TRUE(reply.ok()) << reply.status().ToString();
  return reply.ok() ? nlohmann::json::parse(*reply) : nlohmann::json(nullptr);
}

TEST_F(DaemonIntegrationTest, PressThroughSocketGivesRecordingThenClip) {
  const DaemonConfig config = SmallConfig(dir());
  auto daemon = BuildDaemon(config, {});
  ASSERT_TRUE(daemon.ok()) << daemon.status().ToString();
  std::vector<fs::path> announced;
  std::mutex announced_mutex;
  (*daemon)->SetClipListener([&](const fs::path& clip) {
    std::lock_guard<std::mutex> lock(announced_mutex);
    announced.push_back(clip);
  });
  ASSERT_TRUE((*daemon)->Start().ok());
  auto client = ControlClient::Connect(config.control_socket).value();

  nlohmann::json pressed = Call(*client, R"({"cmd":"capture"})");
  ASSERT_EQ(pressed["ok"], true) << pressed.dump();
  const std::string id = pressed["job"];
  // Generous: the whole job takes about a second here, but CI machines are shared.
  nlohmann::json waited = Call(*client, R"({"cmd":"wait","job":")" + id + R"("})", std::chrono::minutes(5));
  ASSERT_EQ(waited["ok"], true) << waited.dump();
  ASSERT_EQ(waited["job"]["state"], "done") << waited.dump();

  const StorageLayout& layout = (*daemon)->layout();
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
  {
    std::lock_guard<std::mutex> lock(announced_mutex);
    EXPECT_EQ(announced, std::vector<fs::path>{clip});
  }

  nlohmann::json status = Call(*client, R"({"cmd":"status"})");
  EXPECT_EQ(status["state"], "idle");
  EXPECT_EQ(status["jobs"]["done"], 1);
  EXPECT_EQ(status["last_job"]["id"], id);
  EXPECT_EQ(status["last_job"]["state"], "done");
  EXPECT_EQ(status["last_job"]["clip_path"], clip.string());
  EXPECT_THAT(status["last_job"]["note"].get<std::string>(), HasSubstr("9 views"));

  EXPECT_EQ(Call(*client, R"({"cmd":"quit"})")["ok"], true);
  (*daemon)->Wait();
  EXPECT_FALSE(fs::exists(config.control_socket));
}

TEST_F(DaemonIntegrationTest, MissingSceneFileIsAnErrorNamingTheField) {
  DaemonConfig config = SmallConfig(dir());
  config.source.sim.scene = dir() / "no_such_scene.json";
  auto daemon = BuildDaemon(config, {});
  ASSERT_FALSE(daemon.ok());
  EXPECT_THAT(daemon.status().message(), HasSubstr("source.sim"));
  EXPECT_THAT(daemon.status().message(), HasSubstr("no_such_scene.json"));
}

TEST_F(DaemonIntegrationTest, UnknownMoveIsAnErrorNamingTheField) {
  DaemonConfig config = SmallConfig(dir());
  config.clip.move = "barrel_roll";
  auto daemon = BuildDaemon(config, {});
  EXPECT_EQ(daemon.status().message(), "clip.move: 'barrel_roll' is not a known camera move");
}

}  // namespace
}  // namespace px::device
