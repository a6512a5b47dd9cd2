#include "device/clip_job.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "capture/import_images.h"
#include "capture/recording.h"
#include "device/source_registry.h"
#include "pipeline/direct/camera_path.h"
#include "pipeline/io/durable_file.h"
#include "pipeline/render/gl/render_backend.h"
#include "sim/synthetic/synthetic_source.h"
#include "tests/testing/animation_probe.h"
#include "tests/testing/temp_dir.h"
#include "tests/testing/video_probe.h"

namespace px::device {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

// A small camera and a short clip so the whole job runs in about a second on 2 cores:
// a 3x3 lattice of 160x120 tiles, 0.5 s at 10 fps.
ClipJobOptions SmallClipOptions() {
  ClipJobOptions options;
  options.pipeline.direct.duration_s = 0.5;
  options.pipeline.direct.fps = 10;
  options.clip.preset = "ultrafast";
  return options;
}

class ClipJobTest : public px::testing::TempDirTest {
 protected:
  // Captures one frame set from the simulated camera and saves it as a recording.
  fs::path SaveSimRecording(bool with_rig = true) {
    SimSourceSettings settings;
    settings.tile_width = 160;
    settings.tile_height = 120;
    SyntheticSourceOptions options;
    options.camera = SimCameraFromSettings(settings).value();
    auto source = MakeSyntheticSource(options);
    EXPECT_TRUE(source.ok()) << source.status().ToString();
    SourceConfig granted;
    EXPECT_TRUE((*source)->Configure({options.camera.pixel_format, 0, 0, 1}, &granted).ok());
    Recording recording;
    recording.source = (*source)->Describe();
    if (!with_rig) recording.source.rig.reset();
    recording.frames = (*source)->Next(std::chrono::seconds(10)).value();
    recording.created_by = "clip_job_test";
    const fs::path dir_path = dir() / (with_rig ? "capture" : "capture_without_rig");
    Status written = WriteRecording(dir_path, recording);
    EXPECT_TRUE(written.ok()) << written.ToString();
    fs::create_directories(dir() / "clips");
    return dir_path;
  }
  std::vector<std::string> ClipsFolder() {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir() / "clips")) names.push_back(entry.path().filename());
    std::sort(names.begin(), names.end());
    return names;
  }
};

TEST_F(ClipJobTest, MakesAPlayableClipWithItsCameraPathBesideIt) {
  const fs::path recording = SaveSimRecording();
  const fs::path clip = dir() / "clips" / "000001.mp4";
  auto report = RunClipJob(recording, clip, SmallClipOptions());
  ASSERT_TRUE(report.ok()) << report.status().ToString();

  EXPECT_EQ(ClipsFolder(),
            (std::vector<std::string>{
                "000001.json", "000001.mp4", "000001.poster.jpg", "000001.preview.webp", "000001.shot.json"}));
  const int want_frames = NumFrames(10, 0.5);
  EXPECT_EQ(report->frames_written, want_frames);
  EXPECT_EQ(report->pipeline.num_views, 9);
  auto video = px::testing::ProbeVideo(clip);
  ASSERT_TRUE(video.ok()) << video.status().ToString();
  EXPECT_EQ(video->codec, "h264");
  EXPECT_EQ(video->frames_decoded, want_frames);
  EXPECT_EQ(video->width, report->width);
  EXPECT_EQ(video->height, report->height);
  EXPECT_EQ(report->clip_bytes, fs::file_size(clip));

  auto text = ReadFileToString(dir() / "clips" / "000001.json");
  ASSERT_TRUE(text.ok());
  nlohmann::json j = nlohmann::json::parse(*text);
  EXPECT_EQ(j["clip"], clip.string());
  EXPECT_EQ(j["frames"], want_frames);
  EXPECT_DOUBLE_EQ(j["duration_s"].get<double>(), want_frames / 10.0);
  EXPECT_EQ(j["source"], "sim:sim-pop9-160x120");
  EXPECT_TRUE(j["timings_ms"].contains("encode"));
  ASSERT_EQ(j["frame_coverage"].size(), static_cast<size_t>(want_frames));
  EXPECT_GE(j["frame_coverage"][0]["hole_ratio"].get<double>(), 0.0);
  EXPECT_LE(j["frame_coverage"][0]["hole_ratio"].get<double>(), 1.0);
  auto path = CameraPathFromJson(j["camera_path"]);
  ASSERT_TRUE(path.ok()) << path.status().ToString();
  EXPECT_GE(path->keyframes.size(), 2u);
  EXPECT_EQ(path->fps, 10);

  // The poster is the move's far end at the clip's size; the preview loops, small, at 10 fps.
  EXPECT_EQ(j["poster"], (dir() / "clips" / "000001.poster.jpg").string());
  const cv::Mat poster = cv::imread(j["poster"].get<std::string>());
  ASSERT_FALSE(poster.empty());
  EXPECT_EQ(poster.cols, report->width);
  EXPECT_EQ(poster.rows, report->height);
  auto preview = px::testing::ProbeAnimation(j["preview"].get<std::string>());
  ASSERT_TRUE(preview.ok()) << preview.status().ToString();
  EXPECT_EQ(preview->format, "webp");
  EXPECT_EQ(preview->frames, want_frames);  // the clip is at 10 fps already
  EXPECT_EQ(preview->plays, 0);
  EXPECT_LE(std::max(preview->width, preview->height), 320);
  EXPECT_LT(j["preview_bytes"].get<uint64_t>(), 500'000u);
  // The poster is the last frame here (the move's far end), as the clip shows it.
  // (H.264 and JPEG each change it a little: it is much nearer the last frame than the first.)
  EXPECT_LT(cv::norm(poster, video->last_frame, cv::NORM_L1), 0.5 * cv::norm(poster, video->first_frame, cv::NORM_L1));
}

// The clip made on GL (OSMesa, llvmpipe: present on every machine this builds on), and the
// same job with the OSMesa library missing: drawn on the CPU, the JSON saying which and why.
TEST_F(ClipJobTest, RendersOnTheChosenBackEndAndSaysWhichInTheJson) {
  const fs::path recording = SaveSimRecording();
  struct Case {
    const char* name;
    std::string osmesa_library;
    std::string want_backend, want_reason;
  };
  for (const Case& c : {Case{"gl", "libOSMesa.so.8", "gl-osmesa", "gl-osmesa: asked for"},
                        Case{"missing", "libOSMesa-not-here.so.8", "cpu", "libOSMesa-not-here.so.8"}}) {
    SCOPED_TRACE(c.name);
    ClipJobOptions options = SmallClipOptions();
    options.pipeline.render_backend.backend = render::gl::RenderBackend::kOsmesa;
    options.pipeline.render_backend.context.osmesa_library = c.osmesa_library;
    const fs::path clip = dir() / "clips" / (std::string(c.name) + ".mp4");
    auto report = RunClipJob(recording, clip, options);
    ASSERT_TRUE(report.ok()) << report.status().ToString();
    EXPECT_EQ(report->frames_written, NumFrames(10, 0.5));
    auto video = px::testing::ProbeVideo(clip);
    ASSERT_TRUE(video.ok()) << video.status().ToString();
    EXPECT_EQ(video->frames_decoded, NumFrames(10, 0.5));
    auto text = ReadFileToString(dir() / "clips" / (std::string(c.name) + ".json"));
    ASSERT_TRUE(text.ok()) << text.status().ToString();
    const nlohmann::json j = nlohmann::json::parse(*text);
    EXPECT_EQ(j["render_backend"]["name"], c.want_backend);
    EXPECT_THAT(j["render_backend"]["reason"].get<std::string>(), HasSubstr(c.want_reason));
  }
}

// Each format through the whole job: the clip decodes with the job's frame count and size, the
// report names the format, and a second run replaces the first clip (a PNG folder too).
TEST_F(ClipJobTest, WritesEveryClipFormat) {
  const fs::path recording = SaveSimRecording();
  const int want_frames = NumFrames(10, 0.5);
  for (clip::ClipFormat format : {clip::ClipFormat::kGif, clip::ClipFormat::kWebp, clip::ClipFormat::kPng}) {
    SCOPED_TRACE(std::string(clip::ClipFormatName(format)));
    ClipJobOptions options = SmallClipOptions();
    options.clip.format = format;
    const fs::path clip = ClipPathForFormat(dir() / "clips" / "000002.mp4", format);
    for (int run = 0; run < 2; ++run) {
      auto report = RunClipJob(recording, clip, options);
      ASSERT_TRUE(report.ok()) << report.status().ToString();
      EXPECT_EQ(report->format, clip::ClipFormatName(format));
      EXPECT_EQ(report->frames_written, want_frames);
      EXPECT_GT(report->clip_bytes, 0u);
    }
    if (format == clip::ClipFormat::kPng) {
      EXPECT_EQ(clip.filename(), "000002");
      int frames = 0;
      for (const auto& entry : fs::directory_iterator(clip)) frames += entry.path().extension() == ".png";
      EXPECT_EQ(frames, want_frames);
    } else {
      auto probe = px::testing::ProbeAnimation(clip);
      ASSERT_TRUE(probe.ok()) << probe.status().ToString();
      EXPECT_EQ(probe->frames, want_frames);
      EXPECT_EQ(probe->plays, 0);
    }
    auto text = ReadFileToString(dir() / "clips" / "000002.json");
    ASSERT_TRUE(text.ok());
    EXPECT_EQ(nlohmann::json::parse(*text)["format"], clip::ClipFormatName(format));
  }
  // Only the clips, their report and shot: no temporaries, no older PNG folder left aside.
  EXPECT_EQ(ClipsFolder(),
            (std::vector<std::string>{"000002",
                                      "000002.gif",
                                      "000002.json",
                                      "000002.poster.jpg",
                                      "000002.preview.webp",
                                      "000002.shot.json",
                                      "000002.webp"}));
}

// Photos in memory (`parallax clip PHOTOS_FOLDER`): the job runs on the recording as given and the
// report names the folder they came from. Random photos share nothing, so structure from motion
// fails and the clip is the flat pan and zoom, never a failed button.
TEST_F(ClipJobTest, PhotosInMemoryMakeAClipNamedAfterTheirFolder) {
  fs::create_directories(dir() / "photos");
  fs::create_directories(dir() / "clips");
  for (int i = 0; i < 3; ++i) {
    cv::Mat photo(120, 160, CV_8UC3);
    cv::randu(photo, cv::Scalar::all(0), cv::Scalar::all(255));
    ASSERT_TRUE(cv::imwrite((dir() / "photos" / ("p" + std::to_string(i) + ".png")).string(), photo));
  }
  auto photos = ListImages({dir() / "photos"});
  ASSERT_TRUE(photos.ok()) << photos.status().ToString();
  std::vector<std::string> warnings;
  auto recording = RecordingFromImages(*photos, &warnings);
  ASSERT_TRUE(recording.ok()) << recording.status().ToString();
  const fs::path clip = dir() / "clips" / "photos.mp4";
  auto report = RunClipJob(*recording, dir() / "photos", clip, SmallClipOptions());
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_EQ(report->frames_written, NumFrames(10, 0.5));
  EXPECT_EQ(report->pipeline.path.kind, PathKind::kPanZoom2d) << report->pipeline.path.reason;
  auto text = ReadFileToString(dir() / "clips" / "photos.json");
  ASSERT_TRUE(text.ok());
  EXPECT_EQ(nlohmann::json::parse(*text)["recording"], (dir() / "photos").string());
  EXPECT_EQ(nlohmann::json::parse(*text)["source"], "import");
}

// A lattice frame without a rig calibration is processed, not refused: its lattice is found blind
// (a raw sensor's tiles, each turned by its lens, as the pipeline assumes when the recording says
// nothing of its lattice) and its tiles posed by structure from motion.
TEST_F(ClipJobTest, LatticeRecordingWithoutRigIsFoundBlind) {
  const fs::path recording = SaveSimRecording(/*with_rig=*/false);
  auto report = RunClipJob(recording, dir() / "clips" / "x.mp4", SmallClipOptions());
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_EQ(report->pipeline.calibration, "structure from motion (no rig calibration)");
  EXPECT_EQ(report->pipeline.num_views, 9);
  EXPECT_EQ(ClipsFolder(),
            (std::vector<std::string>{"x.json", "x.mp4", "x.poster.jpg", "x.preview.webp", "x.shot.json"}));
}

TEST_F(ClipJobTest, CancelledJobLeavesNoClipOrTemporary) {
  const fs::path recording = SaveSimRecording();
  // Cancel in the middle of rendering, when the encoder already holds a temporary file.
  auto report = RunClipJob(
      recording, dir() / "clips" / "x.mp4", SmallClipOptions(), [&](const std::string& stage, double fraction) {
        return !(stage == "render" && fraction >= 0.6);
      });
  EXPECT_EQ(report.status().code(), StatusCode::kCancelled) << report.status().ToString();
  EXPECT_TRUE(ClipsFolder().empty());
}

TEST_F(ClipJobTest, MissingRecordingIsNotFound) {
  fs::create_directories(dir() / "clips");
  auto report = RunClipJob(dir() / "nothing", dir() / "clips" / "x.mp4", SmallClipOptions());
  EXPECT_EQ(report.status().code(), StatusCode::kNotFound) << report.status().ToString();
  EXPECT_TRUE(ClipsFolder().empty());
}

TEST(ClipJobOptionsTest, BadOptionsNameTheField) {
  ClipJobOptions options = SmallClipOptions();
  options.clip.crf = 99;
  EXPECT_THAT(options.Validate().message(), HasSubstr("crf"));
}

}  // namespace
}  // namespace px::device
