#include "device/config.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "device/daemon_factory.h"
#include "pipeline/io/durable_file.h"
#include "pipeline/render/gl/render_backend.h"
#include "tests/testing/temp_dir.h"

namespace px::device {
namespace {

using ::testing::HasSubstr;
using ConfigFileTest = px::testing::TempDirTest;

std::string ErrorOf(const std::string& text) {
  auto config = DaemonConfigFromJson(nlohmann::json::parse(text));
  return config.ok() ? "OK" : config.status().message();
}

TEST(DaemonConfigTest, EmptyObjectGivesValidDefaults) {
  auto config = DaemonConfigFromJson(nlohmann::json::object());
  ASSERT_TRUE(config.ok()) << config.status().ToString();
  EXPECT_EQ(config->storage.root, "/var/lib/parallax");
  EXPECT_EQ(config->source.kind, "sim");
  EXPECT_EQ(config->source.sim.camera, "pop9");
  EXPECT_EQ(config->clip.fps, 30.0);
  EXPECT_TRUE(DaemonConfig().Validate().ok());
}

TEST(DaemonConfigTest, ReadsEveryField) {
  auto config = DaemonConfigFromJson(nlohmann::json::parse(R"({
    "storage": {"root": "/data/px", "min_free_mb": 80},
    "control": {"socket": "/tmp/px.sock"},
    "source": {"kind": "replay", "timeout_ms": 2500,
               "sim": {"scene": "s.json", "camera": "integral5x4", "tile_width": 160, "tile_height": 120, "seed": 7},
               "replay": {"path": "/rec", "loop": false}},
    "clip": {"move": "establishing_dolly", "duration_s": 0.5, "fps": 10, "crf": 28, "preset": "ultrafast",
             "num_threads": 2, "max_photo_side_px": 1600, "format": "gif", "loop_count": 2, "webp_quality": 60},
    "render": {"backend": "osmesa"},
    "log": {"levels": "info,depth=debug"}})"));
  ASSERT_TRUE(config.ok()) << config.status().ToString();
  EXPECT_EQ(config->storage.root, "/data/px");
  EXPECT_EQ(config->storage.min_free_bytes, 80'000'000u);
  EXPECT_EQ(config->control_socket, "/tmp/px.sock");
  EXPECT_EQ(config->source.kind, "replay");
  EXPECT_EQ(config->source.timeout_ms, 2500);
  EXPECT_EQ(config->source.sim.scene, "s.json");
  EXPECT_EQ(config->source.sim.camera, "integral5x4");
  EXPECT_EQ(config->source.sim.tile_width, 160);
  EXPECT_EQ(config->source.sim.tile_height, 120);
  EXPECT_EQ(config->source.sim.seed, 7u);
  EXPECT_EQ(config->source.replay.path, "/rec");
  EXPECT_FALSE(config->source.replay.loop);
  EXPECT_EQ(config->clip.move, "establishing_dolly");
  EXPECT_EQ(config->clip.duration_s, 0.5);
  EXPECT_EQ(config->clip.fps, 10.0);
  EXPECT_EQ(config->clip.crf, 28);
  EXPECT_EQ(config->clip.preset, "ultrafast");
  EXPECT_EQ(config->clip.num_threads, 2);
  EXPECT_EQ(config->clip.max_photo_side_px, 1600);
  EXPECT_EQ(config->clip.format, "gif");
  EXPECT_EQ(config->clip.loop_count, 2);
  EXPECT_EQ(config->clip.webp_quality, 60);
  EXPECT_EQ(config->render.backend, "osmesa");
  EXPECT_EQ(ClipJobOptionsFromConfig(*config)->pipeline.render_backend.backend, render::gl::RenderBackend::kOsmesa);
  EXPECT_EQ(config->log_levels, "info,depth=debug");
}

// The daemon directs clips with faces when the cascades are there, and without them (a warning,
// not a dead daemon) when they are not or when switched off.
TEST(DaemonConfigTest, FaceCascadesGiveTheJobsAFaceDetector) {
  DaemonConfig config;
  if (!std::filesystem::exists(config.clip.face_cascades / "haarcascade_frontalface_default.xml")) {
    GTEST_SKIP() << "no OpenCV cascades in " << config.clip.face_cascades << " (install opencv-data)";
  }
  auto with_faces = ClipJobOptionsFromConfig(config);
  ASSERT_TRUE(with_faces.ok()) << with_faces.status().ToString();
  EXPECT_NE(with_faces->pipeline.face_detector, nullptr);
  config.clip.face_cascades = "/nonexistent/cascades";
  auto missing = ClipJobOptionsFromConfig(config);
  ASSERT_TRUE(missing.ok()) << missing.status().ToString();
  EXPECT_EQ(missing->pipeline.face_detector, nullptr);
  config.clip.face_cascades.clear();
  auto off = ClipJobOptionsFromConfig(config);
  ASSERT_TRUE(off.ok());
  EXPECT_EQ(off->pipeline.face_detector, nullptr);
  auto round_trip = DaemonConfigFromJson(nlohmann::json::parse(R"({"clip": {"face_cascades": "/x/y"}})"));
  ASSERT_TRUE(round_trip.ok()) << round_trip.status().ToString();
  EXPECT_EQ(round_trip->clip.face_cascades, "/x/y");
}

TEST(DaemonConfigTest, ErrorsNameTheField) {
  EXPECT_EQ(ErrorOf(R"({"clip": {"fps": 0}})"), "clip.fps: 0 is not in (0, 240]");
  EXPECT_EQ(ErrorOf(R"({"clip": {"fps": "fast"}})"), "clip.fps: want a number, got string");
  EXPECT_EQ(ErrorOf(R"({"clip": {"crf": 60}})"), "clip.crf: 60 is not in [0, 51]");
  EXPECT_EQ(ErrorOf(R"({"clip": {"duration_s": -1}})"), "clip.duration_s: -1 is not in (0, 60]");
  EXPECT_THAT(ErrorOf(R"({"clip": {"preset": "warp"}})"), HasSubstr("clip.preset: 'warp' is not one of"));
  EXPECT_EQ(ErrorOf(R"({"clip": {"format": "avi"}})"), "clip.format: \"avi\" is not one of mp4, gif, webp, png");
  EXPECT_EQ(ErrorOf(R"({"clip": {"loop_count": -1}})"), "clip.loop_count: -1 is not in [0, 65535] (0 = forever)");
  EXPECT_EQ(ErrorOf(R"({"clip": {"webp_quality": 101}})"), "clip.webp_quality: 101 is not in [0, 100]");
  EXPECT_EQ(ErrorOf(R"({"clip": {"max_photo_side_px": 32}})"),
            "clip.max_photo_side_px: 32 is not in 0 (full size) or [64, 16384]");
  EXPECT_THAT(ErrorOf(R"({"source": {"kind": "webcam"}})"),
              HasSubstr("source.kind: 'webcam' is not one of sim, replay"));
  EXPECT_EQ(ErrorOf(R"({"source": {"sim": {"camera": "pop4"}}})"),
            "source.sim.camera: 'pop4' is not one of pop9, integral5x4");
  EXPECT_EQ(ErrorOf(R"({"source": {"kind": "replay"}})"), "source.replay.path: empty, but source.kind is replay");
  EXPECT_EQ(ErrorOf(R"({"source": {"sim": {"seed": -3}}})"), "source.sim.seed: -3 is negative");
  EXPECT_EQ(ErrorOf(R"({"source": {"sim": 5}})"), "source.sim: want an object, got number");
  EXPECT_EQ(ErrorOf(R"({"storage": {"root": ""}})"), "storage.root: empty");
  EXPECT_EQ(ErrorOf(R"({"storage": {"min_free_mb": -1}})"), "storage.min_free_mb: -1 is not in [0, 1e9)");
  EXPECT_EQ(ErrorOf(R"({"render": {"backend": "vulkan"}})"),
            "render.backend: 'vulkan' is not one of auto, cpu, egl, osmesa");
  EXPECT_EQ(ErrorOf(R"({"clip": {"style": "spiral"}})"), "clip.style: 'spiral' is not one of once, loop, boomerang");
  EXPECT_EQ(ErrorOf(R"({"clip": {"ease": "bouncy"}})"), "clip.ease: 'bouncy' is not one of linear, smooth");
  EXPECT_EQ(ErrorOf(R"({"clip": {"style": "loop", "hold_s": 1}})"),
            "clip.hold_s: only a clip played once holds its last frame (clip.style is loop)");
  EXPECT_EQ(ErrorOf(R"({"clip": {"size": "big"}})"), "clip.size: size 'big': want WIDTHxHEIGHT, e.g. 1080x1920");
  EXPECT_EQ(ErrorOf(R"({"clip": {"aspect": "tall"}})"),
            "clip.aspect: aspect 'tall': want W:H (16:9, 9:16, 1:1, 4:5) or source");
  EXPECT_EQ(ErrorOf(R"({"clip": {"aspect": "9:16", "height": 5}})"),
            "clip.height: output height 5 is not within 16..8192");
  EXPECT_EQ(ErrorOf(R"({"worker": {"memory_limit_mb": 10}})"),
            "worker.memory_limit_mb: 10 is not in 0 or [64, 1048576]");
  EXPECT_EQ(ErrorOf(R"({"worker": {"timeout_s": 5}})"), "worker.timeout_s: 5 is not in [10, 86400]");
  EXPECT_EQ(ErrorOf(R"({"worker": {"max_crashes": 0}})"), "worker.max_crashes: 0 is not in [1, 100]");
  EXPECT_EQ(ErrorOf(R"({"http": {"listen": "8080"}})"), "http.listen: '8080' is not HOST:PORT (e.g. 127.0.0.1:8080)");
  EXPECT_EQ(ErrorOf(R"({"http": {"listen": "0.0.0.0:99999"}})"),
            "http.listen: '0.0.0.0:99999' is not HOST:PORT (e.g. 127.0.0.1:8080)");
  EXPECT_EQ(ErrorOf(R"({"http": {"token_required": "never"}})"),
            "http.token_required: 'never' is not one of remote, always");
  EXPECT_EQ(ErrorOf(R"({"http": {"max_body_kb": 0}})"), "http.max_body_kb: 0 is not in [1, 65536]");
  EXPECT_EQ(ErrorOf(R"({"http": {"max_event_streams": 100}})"), "http.max_event_streams: 100 is not in [1, 64]");
  EXPECT_EQ(ErrorOf(R"([1, 2])"), "config: want an object, got array");
}

TEST(DaemonConfigTest, WebAppListensOnLoopbackByDefault) {
  const DaemonConfig config;
  EXPECT_EQ(config.http.listen, "127.0.0.1:8080");
  EXPECT_EQ(config.http.token_required, "remote");
  auto off = DaemonConfigFromJson(nlohmann::json::parse(R"({"http": {"listen": ""}})"));
  ASSERT_TRUE(off.ok()) << off.status().ToString();
  EXPECT_EQ(off->http.listen, "");
  auto anywhere =
      DaemonConfigFromJson(nlohmann::json::parse(R"({"http": {"listen": "[::]:80", "token_required": "always"}})"));
  ASSERT_TRUE(anywhere.ok()) << anywhere.status().ToString();
  EXPECT_EQ(anywhere->http.token_required, "always");
}

TEST(DaemonConfigTest, ReadsAndChecksTheV4l2Source) {
  auto config = DaemonConfigFromJson(nlohmann::json::parse(R"({"source": {"kind": "v4l2",
    "v4l2": {"device": "/dev/video2", "pixel_format": "YUYV", "width": 504, "height": 384,
             "rig_calibration": "/etc/parallax/rig.json", "exposure": 300, "gain": 16}}})"));
  ASSERT_TRUE(config.ok()) << config.status().ToString();
  EXPECT_EQ(config->source.kind, "v4l2");
  EXPECT_EQ(config->source.v4l2.device, "/dev/video2");
  EXPECT_EQ(config->source.v4l2.pixel_format, "YUYV");
  EXPECT_EQ(config->source.v4l2.width, 504);
  EXPECT_EQ(config->source.v4l2.height, 384);
  EXPECT_EQ(config->source.v4l2.rig_calibration, "/etc/parallax/rig.json");
  EXPECT_EQ(config->source.v4l2.exposure, 300);
  EXPECT_EQ(config->source.v4l2.gain, 16);
  // Defaults: /dev/video0, RGB888, native size, controls left alone.
  const V4l2SourceSettings defaults = DaemonConfig().source.v4l2;
  EXPECT_EQ(defaults.device, "/dev/video0");
  EXPECT_EQ(defaults.exposure, -1);
  EXPECT_EQ(defaults.gain, -1);
  const nlohmann::json printed = DaemonConfigToJson(*config);
  EXPECT_EQ(printed["source"]["v4l2"]["exposure"], 300);
  EXPECT_EQ(DaemonConfigToJson(DaemonConfigFromJson(printed).value()), printed);

  EXPECT_EQ(ErrorOf(R"({"source": {"v4l2": {"pixel_format": "MJPG"}}})"),
            "source.v4l2.pixel_format: 'MJPG' is not one of RGB888, BGR888, GRAY8, YUYV, NV12, SRGGB8");
  EXPECT_EQ(ErrorOf(R"({"source": {"v4l2": {"width": 640}}})"), "source.v4l2.width, height: give both or neither");
  EXPECT_EQ(ErrorOf(R"({"source": {"v4l2": {"exposure": -5}}})"),
            "source.v4l2.exposure: -5 is not in [-1, ...) (-1 = leave)");
  EXPECT_EQ(ErrorOf(R"({"source": {"v4l2": {"device": ""}}})"), "source.v4l2.device: empty");
  EXPECT_THAT(ErrorOf(R"({"source": {"v4l2": {"fps": 30}}})"),
              HasSubstr("source.v4l2.fps: unknown field (known: device, pixel_format, width, height, rig_calibration, "
                        "exposure, gain)"));
}

TEST(DaemonConfigTest, ReadsAndChecksThePtpSource) {
  auto config = DaemonConfigFromJson(nlohmann::json::parse(R"({"source": {"kind": "ptp",
    "ptp": {"vendor_id": "04a9", "product_id": "3218", "shots": 9, "timeout_ms": 4000}}})"));
  ASSERT_TRUE(config.ok()) << config.status().ToString();
  EXPECT_EQ(config->source.kind, "ptp");
  EXPECT_EQ(config->source.ptp.vendor_id, "04a9");
  EXPECT_EQ(config->source.ptp.product_id, "3218");
  EXPECT_EQ(config->source.ptp.shots, 9);
  EXPECT_EQ(config->source.ptp.timeout_ms, 4000);
  // Defaults: the first PTP camera, 5 shots, 10 s per shot.
  const PtpSourceSettings defaults = DaemonConfig().source.ptp;
  EXPECT_EQ(defaults.vendor_id, "");
  EXPECT_EQ(defaults.shots, 5);
  EXPECT_EQ(defaults.timeout_ms, 10000);
  const nlohmann::json printed = DaemonConfigToJson(*config);
  EXPECT_EQ(printed["source"]["ptp"]["shots"], 9);
  EXPECT_EQ(DaemonConfigToJson(DaemonConfigFromJson(printed).value()), printed);

  EXPECT_EQ(ErrorOf(R"({"source": {"ptp": {"shots": 1}}})"), "source.ptp.shots: 1 is not in [2, 15]");
  EXPECT_EQ(ErrorOf(R"({"source": {"ptp": {"shots": 16}}})"), "source.ptp.shots: 16 is not in [2, 15]");
  EXPECT_EQ(ErrorOf(R"({"source": {"ptp": {"timeout_ms": 0}}})"), "source.ptp.timeout_ms: 0 is not in (0, 600000]");
  EXPECT_EQ(ErrorOf(R"({"source": {"ptp": {"vendor_id": "canon"}}})"),
            "source.ptp.vendor_id: 'canon' is not 4 hex digits (e.g. 04a9)");
  EXPECT_EQ(ErrorOf(R"({"source": {"ptp": {"vendor_id": "04a9", "product_id": "32"}}})"),
            "source.ptp.product_id: '32' is not 4 hex digits (e.g. 3218)");
  EXPECT_EQ(ErrorOf(R"({"source": {"ptp": {"product_id": "3218"}}})"),
            "source.ptp.product_id: given without source.ptp.vendor_id");
  EXPECT_THAT(ErrorOf(R"({"source": {"ptp": {"shot": 3}}})"),
              HasSubstr("source.ptp.shot: unknown field (known: vendor_id, product_id, shots, timeout_ms)"));
}

TEST(DaemonConfigTest, UnknownFieldsAreErrorsListingTheKnownOnes) {
  EXPECT_EQ(ErrorOf(R"({"source": {"sim": {"camra": "pop9"}}})"),
            "source.sim.camra: unknown field (known: scene, camera, tile_width, tile_height, seed)");
  EXPECT_THAT(ErrorOf(R"({"clips": {}})"), HasSubstr("clips: unknown field (known: storage, control, source"));
}

TEST(DaemonConfigTest, PrintedConfigParsesBackToTheSameConfig) {
  DaemonConfig config;
  config.storage.root = "/somewhere/else";
  config.storage.min_free_bytes = 1'500'000;
  config.control_socket = "";
  config.source.kind = "replay";
  config.source.replay.path = "/recordings";
  config.source.sim.tile_width = 160;
  config.clip.duration_s = 0.5;
  config.clip.fps = 12.5;
  config.log_levels = "warn";
  config.clip.style = "boomerang";
  config.clip.ease = "linear";
  config.clip.aspect = "9:16";
  config.clip.height = 1920;
  config.worker.memory_limit_mb = 2048;
  config.worker.timeout_s = 120;
  config.worker.max_crashes = 5;
  config.http.listen = "0.0.0.0:9000";
  config.http.requests_per_s = 7;
  const nlohmann::json printed = DaemonConfigToJson(config);
  auto parsed = DaemonConfigFromJson(nlohmann::json::parse(printed.dump(2)));
  ASSERT_TRUE(parsed.ok()) << parsed.status().ToString();
  EXPECT_EQ(DaemonConfigToJson(*parsed), printed);
  EXPECT_EQ(parsed->storage.min_free_bytes, 1'500'000u);
  // The defaults round-trip as well.
  EXPECT_EQ(DaemonConfigToJson(DaemonConfigFromJson(DaemonConfigToJson(DaemonConfig())).value()),
            DaemonConfigToJson(DaemonConfig()));
}

TEST_F(ConfigFileTest, LookupOrderIsFlagThenEnvironmentThenDefaults) {
  const auto flag_file = dir() / "flag.json";
  const auto env_file = dir() / "env.json";
  ASSERT_TRUE(WriteFileAtomically(flag_file, R"({"clip": {"fps": 12}})").ok());
  ASSERT_TRUE(WriteFileAtomically(env_file, R"({"clip": {"fps": 24}})").ok());

  auto from_flag = ResolveDaemonConfig(flag_file.string(), env_file.c_str());
  ASSERT_TRUE(from_flag.ok()) << from_flag.status().ToString();
  EXPECT_EQ(from_flag->config.clip.fps, 12.0);
  EXPECT_EQ(from_flag->origin, "--config " + flag_file.string());

  auto from_env = ResolveDaemonConfig("", env_file.c_str());
  ASSERT_TRUE(from_env.ok());
  EXPECT_EQ(from_env->config.clip.fps, 24.0);
  EXPECT_EQ(from_env->origin, "$PARALLAX_CONFIG=" + env_file.string());

  auto defaults = ResolveDaemonConfig("", "");
  ASSERT_TRUE(defaults.ok());
  EXPECT_EQ(defaults->config.clip.fps, 30.0);
  EXPECT_EQ(defaults->origin, "built-in defaults");
  EXPECT_TRUE(ResolveDaemonConfig("", nullptr).ok());
}

TEST_F(ConfigFileTest, FileErrorsNameTheFileAndField) {
  const auto bad = dir() / "bad.json";
  ASSERT_TRUE(WriteFileAtomically(bad, R"({"clip": {"crf": 99}})").ok());
  auto config = ResolveDaemonConfig(bad.string(), nullptr);
  ASSERT_FALSE(config.ok());
  EXPECT_EQ(config.status().message(), bad.string() + ": clip.crf: 99 is not in [0, 51]");

  const auto broken = dir() / "broken.json";
  ASSERT_TRUE(WriteFileAtomically(broken, R"({"clip": )").ok());
  EXPECT_THAT(ResolveDaemonConfig("", broken.c_str()).status().message(),
              HasSubstr("$PARALLAX_CONFIG: " + broken.string() + ": malformed JSON at byte"));

  auto missing = ResolveDaemonConfig((dir() / "absent.json").string(), nullptr);
  EXPECT_EQ(missing.status().code(), StatusCode::kNotFound);
  EXPECT_THAT(missing.status().message(), HasSubstr("absent.json"));
}

}  // namespace
}  // namespace px::device
