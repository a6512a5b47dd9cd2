// One photo holding a lattice of views, as `parallax import --lattice` and `parallax clip FRAME.jpg`
// take it: a synthetic strip of four views (a Nishika scan: dark gaps, each frame exposed a little
// differently) and a 2x2 of abutting, vignetted views (a multi-lens frame whose tiles touch),
// written as JPEG, imported without a rig calibration, split blind (or evenly: at the size given,
// or where equal tiles show one scene) and posed by structure from motion into a 3D move; a photo
// of no lattice still gives a clip; a real ActionSampler scan gives a morph.
#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "capture/import_images.h"
#include "capture/recording.h"
#include "device/clip_job.h"
#include "sim/synthetic/data_paths.h"
#include "sim/synthetic/ray_caster.h"
#include "sim/synthetic/scene_json.h"
#include "tests/testing/temp_dir.h"

namespace px {
namespace {

namespace fs = std::filesystem;

const CameraModel kTile = CameraModel::Pinhole(320, 240, 280);

// The still life seen from `count` lenses in a row, 3 cm apart, each picture upright.
std::vector<cv::Mat> RowOfViews(int count) {
  const sim::Scene scene = sim::LoadScene(sim::ScenesDir() / "still_life.json").value();
  std::vector<cv::Mat> views;
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3d centre((i - (count - 1) / 2.0) * 0.03, 0, 0);
    views.push_back(sim::RenderView(scene, kTile, Rigid3(Eigen::Quaterniond::Identity(), -centre)).value().bgr);
  }
  return views;
}

// A scan of a strip: the views side by side on black film, 14 px apart, each exposed by its own gain.
cv::Mat Strip(const std::vector<cv::Mat>& views) {
  constexpr int kGap = 14;
  const double gains[] = {0.85, 1.0, 1.1, 0.93};
  cv::Mat frame(kTile.height + 2 * kGap,
                static_cast<int>(views.size()) * (kTile.width + kGap) + kGap,
                CV_8UC3,
                cv::Scalar(8, 8, 8));
  for (size_t i = 0; i < views.size(); ++i) {
    cv::Mat exposed;
    views[i].convertTo(exposed, -1, gains[i % 4]);
    exposed.copyTo(frame(cv::Rect(kGap + static_cast<int>(i) * (kTile.width + kGap), kGap, kTile.width, kTile.height)));
  }
  return frame;
}

// A 2x2 of views that touch, each darkened towards its corners as a cheap lens vignettes.
cv::Mat AbuttingSquare(const std::vector<cv::Mat>& views) {
  cv::Mat frame(2 * kTile.height, 2 * kTile.width, CV_8UC3);
  for (int i = 0; i < 4; ++i) {
    cv::Mat vignetted = views[i].clone();
    for (int y = 0; y < kTile.height; ++y) {
      for (int x = 0; x < kTile.width; ++x) {
        const double dx = (x - kTile.cx) / kTile.width, dy = (y - kTile.cy) / kTile.height;
        vignetted.at<cv::Vec3b>(y, x) *= std::max(0.35, 1.0 - 1.3 * (dx * dx + dy * dy));
      }
    }
    vignetted.copyTo(frame(cv::Rect((i % 2) * kTile.width, (i / 2) * kTile.height, kTile.width, kTile.height)));
  }
  return frame;
}

class LatticePhotoTest : public testing::TempDirTest {
 protected:
  // The photo imported as `parallax import --lattice SIZE` does, then made into a short clip.
  StatusOr<device::ClipJobReport> Clip(const cv::Mat& photo, const std::string& size) {
    const fs::path file = dir() / "frame.jpg";
    EXPECT_TRUE(cv::imwrite(file.string(), photo, {cv::IMWRITE_JPEG_QUALITY, 95}));
    return ClipFile(file, size);
  }

  StatusOr<device::ClipJobReport> ClipFile(const fs::path& file, const std::string& size) {
    std::vector<std::string> warnings;
    PX_ASSIGN_OR_RETURN(LatticeHint hint, ParseLatticeSize(size));
    PX_ASSIGN_OR_RETURN(Recording recording, RecordingFromLatticePhoto(file, hint, &warnings));
    EXPECT_EQ(recording.frames.kind, FrameSetKind::kLatticeFrame);
    EXPECT_FALSE(recording.source.rig.has_value());
    PX_RETURN_IF_ERROR(WriteRecording(dir() / "recording", recording));
    device::ClipJobOptions options;
    options.pipeline.direct.duration_s = 0.5;
    options.pipeline.direct.fps = 10;
    options.clip.preset = "ultrafast";
    fs::create_directories(dir() / "clips");
    return device::RunClipJob(dir() / "recording", dir() / "clips" / "frame.mp4", options);
  }
};

TEST_F(LatticePhotoTest, AStripScanIsFoundBlindAndPosed) {
  StatusOr<device::ClipJobReport> report = Clip(Strip(RowOfViews(4)), "auto");
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_EQ(report->pipeline.calibration, "structure from motion (no rig calibration)");
  EXPECT_EQ(report->pipeline.num_views, 4);
  EXPECT_EQ(report->pipeline.path.kind, PathKind::kNovelView) << report->pipeline.path.reason;
}

TEST_F(LatticePhotoTest, AbuttingTilesOfAGivenSizeAreCutEvenly) {
  StatusOr<device::ClipJobReport> report = Clip(AbuttingSquare(RowOfViews(4)), "2x2");
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_EQ(report->pipeline.num_views, 4);
  EXPECT_TRUE(std::any_of(report->pipeline.warnings.begin(), report->pipeline.warnings.end(), [](const std::string& w) {
    return w.find("cut evenly") != std::string::npos;
  })) << ::testing::PrintToString(report->pipeline.warnings);
}

TEST_F(LatticePhotoTest, AbuttingTilesAreFoundByTheirPicturesWithoutTheirSize) {
  StatusOr<device::ClipJobReport> report = Clip(AbuttingSquare(RowOfViews(4)), "auto");
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_EQ(report->pipeline.num_views, 4);
  EXPECT_TRUE(std::any_of(report->pipeline.warnings.begin(), report->pipeline.warnings.end(), [](const std::string& w) {
    return w.find("2 columns x 2 rows cut evenly") != std::string::npos &&
           w.find("show one scene") != std::string::npos;
  })) << ::testing::PrintToString(report->pipeline.warnings);
}

TEST_F(LatticePhotoTest, APhotoOfNoLatticeStillGivesAClipAndSaysWhy) {
  StatusOr<device::ClipJobReport> report = Clip(RowOfViews(1)[0], "auto");
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_EQ(report->pipeline.path.kind, PathKind::kPanZoom2d);
  EXPECT_TRUE(std::any_of(report->pipeline.warnings.begin(), report->pipeline.warnings.end(), [](const std::string& w) {
    return w.find("lattice frame without calibration") != std::string::npos &&
           w.find("cannot be found blind") != std::string::npos;
  })) << ::testing::PrintToString(report->pipeline.warnings);
}

// A real film scan (../shared/data): four lenses fired in sequence, exposed and vignetted each
// its own way, a close-up face over a dark, grainy surround. Its depth is not trusted for a 3D
// move; the clip morphs between two of its lenses, not a flat pan.
TEST_F(LatticePhotoTest, TheRealActionSamplerScanMorphsBetweenTwoLenses) {
  const fs::path file = sim::SharedDataDir() / "lattice_frames" / "actionsampler_2x2_face" / "imm000_0.jpg";
  if (!fs::exists(file)) GTEST_SKIP() << "real data absent: " << file.string();
  StatusOr<device::ClipJobReport> report = ClipFile(file, "auto");
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_EQ(report->pipeline.num_views, 4);
  EXPECT_EQ(report->pipeline.path.kind, PathKind::kMorph) << report->pipeline.path.reason << "\n"
                                                          << ::testing::PrintToString(report->pipeline.warnings);
}

TEST(LatticeSizeTest, AutoOrRowsByColumns) {
  EXPECT_EQ(ParseLatticeSize("auto")->rows, 0);
  EXPECT_EQ(ParseLatticeSize("1x4")->cols, 4);
  EXPECT_EQ(ParseLatticeSize("3X3")->rows, 3);
  for (const char* bad : {"", "1x1", "0x4", "4x", "x4", "2x2x2", "17x1", "two"}) {
    EXPECT_FALSE(ParseLatticeSize(bad).ok()) << bad;
  }
}

}  // namespace
}  // namespace px
