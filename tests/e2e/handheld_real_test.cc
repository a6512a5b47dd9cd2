// Real hand-held photos (../shared/data/handheld: phone shots from 2 to 4 places) imported as
// `parallax import` does and run through the whole pipeline at the product's working size:
// every set gives a clip, never a failed button. Prints per set the working size, the move and
// why, the stage times. The office set (a sideways sweep, its centres nearly on a line) once
// failed in the view mesh; the 8 MP excavator took 68 s and 4.5 GB at full size.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <filesystem>

#include "capture/import_images.h"
#include "pipeline/run/pipeline.h"
#include "sim/synthetic/data_paths.h"
#include "tests/testing/counting_frame_sink.h"

namespace px {
namespace {

struct Expected {
  const char* set;
  bool three_d;  // a 3D move (else a morph or a flat pan and zoom, with the reason)
};

class HandheldRealTest : public ::testing::TestWithParam<Expected> {};

TEST_P(HandheldRealTest, MakesAClipAtTheWorkingSize) {
  const std::filesystem::path dir = sim::SharedDataDir() / "handheld" / GetParam().set;
  if (!std::filesystem::exists(dir)) GTEST_SKIP() << "hand-held photos absent: " << dir.string();
  StatusOr<std::vector<std::filesystem::path>> files = ListImages({dir});
  ASSERT_TRUE(files.ok()) << files.status().ToString();
  std::vector<std::string> warnings;
  StatusOr<Recording> recording = RecordingFromImages(*files, &warnings);
  ASSERT_TRUE(recording.ok()) << recording.status().ToString();

  PipelineOptions options;  // the product's, at 5 frames
  options.direct.fps = 5;
  options.direct.duration_s = 1;
  testing::CountingFrameSink sink;
  const auto start = std::chrono::steady_clock::now();
  StatusOr<PipelineReport> report = RunPipeline(recording->frames, RigCalibration{}, options, &sink);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_EQ(sink.frames, 5);
  EXPECT_LE(std::max(sink.size.width, sink.size.height), options.image_set_max_side_px);
  EXPECT_EQ(report->path.kind == PathKind::kNovelView, GetParam().three_d) << report->path.reason;
  if (report->path.kind != PathKind::kNovelView) {
    EXPECT_FALSE(report->path.reason.empty());
  }
  std::printf(
      "[figures] %s: %zu photos of %dx%d -> %dx%d clip; %s (%s); %.0f%% depth confident, %.0f%% "
      "confirmed by another view; %.1f s (5 frames)\n",
      GetParam().set,
      files->size(),
      recording->frames.frames[0].image.width,
      recording->frames.frames[0].image.height,
      sink.size.width,
      sink.size.height,
      report->path.move.c_str(),
      report->calibration.c_str(),
      100 * report->depth.confident_fraction,
      100 * report->depth.consistent_fraction,
      seconds);
}

// Which sets hold a 3D move is measured, not wished: in the excavator (wide turns) and the
// portrait (two different people) another view confirms under 40 % of the depth; the French
// press's plain wall leaves under a fifth of its depth confident, but over 70 % of it confirmed,
// enough (its held-out views: eval real).
INSTANTIATE_TEST_SUITE_P(Sets,
                         HandheldRealTest,
                         ::testing::Values(Expected{"kpankov_office_4views", true},
                                           Expected{"kpankov_frenchpress_4views", true},
                                           Expected{"ddd_seattle_portrait_2views", false},
                                           Expected{"ddd_lego_excavator_3views", false}),
                         [](const ::testing::TestParamInfo<Expected>& param) {
                           std::string name = param.param.set;
                           for (char& c : name) c = std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
                           return name;
                         });

}  // namespace
}  // namespace px
