// A real Nintendo 3DS pair (../shared/data/mpo): two views a few centimetres apart whose valid
// viewpoints form two narrow regions. Asked for an establishing dolly, the direction stage finds a
// path whose frames hold at the output size: its search at 1/8 size reads the frames the renderer
// draws (the coarse scene follows the drawn planes) and leaves out paths that cross the gap
// between the regions. Left to choose, it morphs: that path shows almost no parallax.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "capture/import_images.h"
#include "capture/recording.h"
#include "device/clip_job.h"
#include "sim/synthetic/data_paths.h"
#include "tests/testing/temp_dir.h"

namespace px {
namespace {

namespace fs = std::filesystem;

class StereoMoveRealTest : public testing::TempDirTest {
 protected:
  void SetUp() override {
    const fs::path file = sim::SharedDataDir() / "mpo" / "nintendo3ds_mpo" / "sugarshack.mpo";
    if (!fs::exists(file)) GTEST_SKIP() << "real data absent: " << file.string();
    std::vector<std::string> warnings;
    StatusOr<Recording> recording = RecordingFromImages({file}, &warnings);
    ASSERT_TRUE(recording.ok()) << recording.status().ToString();
    ASSERT_TRUE(WriteRecording(dir() / "recording", *recording).ok());
    fs::create_directories(dir() / "clips");
  }

  StatusOr<device::ClipJobReport> Clip(const std::string& move) {
    device::ClipJobOptions options;
    options.pipeline.direct.move = move;
    options.pipeline.direct.duration_s = 0.5;
    options.pipeline.direct.fps = 10;
    options.clip.preset = "ultrafast";
    return device::RunClipJob(dir() / "recording", dir() / "clips" / (move + ".mp4"), options);
  }
};

TEST_F(StereoMoveRealTest, AnAskedDollyHoldsAtTheOutputSize) {
  StatusOr<device::ClipJobReport> report = Clip("establishing_dolly");
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_EQ(report->pipeline.path.kind, PathKind::kNovelView) << report->pipeline.path.reason << "\n"
                                                              << ::testing::PrintToString(report->pipeline.warnings);
}

TEST_F(StereoMoveRealTest, LeftToChooseItMorphsRatherThanZoomIntoAFlatPicture) {
  StatusOr<device::ClipJobReport> report = Clip("auto");
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_EQ(report->pipeline.path.kind, PathKind::kMorph) << report->pipeline.path.reason;
  EXPECT_TRUE(std::any_of(report->pipeline.warnings.begin(), report->pipeline.warnings.end(), [](const std::string& w) {
    return w.find("almost no parallax") != std::string::npos;
  })) << ::testing::PrintToString(report->pipeline.warnings);
}

}  // namespace
}  // namespace px
