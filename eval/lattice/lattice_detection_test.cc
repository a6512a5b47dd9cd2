// Lattice detection on simulated frames with known layouts (regular, unequal, offset, turned
// tiles; distortion, vignetting, noise), near a prior, on the real lattice frames (an ActionSampler
// and a Nishika scan, a wiggle lens's abutting views), and its refusals (real single photos among
// them).
#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "eval/lattice/lattice_eval.h"
#include "pipeline/lattice/split_lattice.h"
#include "pipeline/lattice/tile_agreement.h"
#include "sim/synthetic/data_paths.h"
#include "sim/synthetic/scene_json.h"

namespace px::eval {
namespace {

namespace fs = std::filesystem;

sim::Scene StillLife() {
  StatusOr<sim::Scene> scene = sim::LoadScene(sim::ScenesDir() / "still_life.json");
  EXPECT_TRUE(scene.ok()) << scene.status().message();
  return *scene;
}

SimLatticeCase Case(const std::string& name) {
  for (const SimLatticeCase& c : StandardSimLatticeCases(0.5)) {
    if (c.name == name) return c;
  }
  ADD_FAILURE() << "no case " << name;
  return {};
}

// Tile corners within 2 px of the truth: the edges are fitted to a fraction of a pixel, and the
// simulated outline is itself anti-aliased over one pixel; rects are whole pixels (0.5 px per side).
constexpr double kMaxCornerErrorPx = 2.0;
constexpr double kMaxRotationErrorDeg = 0.25;

void ExpectFound(const SimLatticeCase& c, int rows, int cols) {
  StatusOr<LatticeEvalRow> row = EvaluateSimLatticeCase(StillLife(), c, 5);
  ASSERT_TRUE(row.ok()) << row.status().message();
  ASSERT_TRUE(row->found) << c.name << ": " << row->error;
  EXPECT_EQ(row->rows, rows);
  EXPECT_EQ(row->cols, cols);
  EXPECT_LT(row->layout_error.max_corner_px, kMaxCornerErrorPx) << c.name;
  EXPECT_LT(row->layout_error.max_rotation_deg, kMaxRotationErrorDeg) << c.name;
  EXPECT_GT(row->confidence, 0.5) << row->summary;
  std::printf("%s", FormatLatticeRows({*row}).c_str());
}

TEST(LatticeDetectionTest, Finds2x2) { ExpectFound(Case("sim 2x2 regular"), 2, 2); }
TEST(LatticeDetectionTest, Finds3x3) { ExpectFound(Case("sim 3x3 regular"), 3, 3); }
TEST(LatticeDetectionTest, Finds5x4) { ExpectFound(Case("sim 5x4 regular"), 4, 5); }
TEST(LatticeDetectionTest, FindsUnequalOffsetTurned2x2) { ExpectFound(Case("sim 2x2 varied"), 2, 2); }
TEST(LatticeDetectionTest, FindsUnequalOffsetTurned3x3) { ExpectFound(Case("sim 3x3 varied"), 3, 3); }
TEST(LatticeDetectionTest, FindsUnequalOffsetTurned5x4) { ExpectFound(Case("sim 5x4 varied"), 4, 5); }

TEST(LatticeDetectionTest, VariedTilesReallyDifferFromTheRegularGrid) {
  const SimLatticeCase c = Case("sim 3x3 varied");
  StatusOr<LatticeLayout> varied = sim::VariedLayout(c.spec, c.variation);
  ASSERT_TRUE(varied.ok()) << varied.status().message();
  double max_rotation = 0;
  std::set<int> widths;
  for (const Tile& t : varied->tiles) {
    max_rotation = std::max(max_rotation, std::abs(t.rotation_deg));
    widths.insert(t.rect.width);
  }
  EXPECT_GT(max_rotation, 0.3);
  EXPECT_GT(widths.size(), 1u);
}

TEST(LatticeDetectionTest, NearAPriorReportsItsShift) {
  const SimLatticeCase c = Case("sim 3x3 varied, prior 7 px off");
  StatusOr<LatticeEvalRow> row = EvaluateSimLatticeCase(StillLife(), c, 5);
  ASSERT_TRUE(row.ok()) << row.status().message();
  ASSERT_TRUE(row->found) << row->error;
  EXPECT_LT(row->layout_error.max_corner_px, kMaxCornerErrorPx);
  // The prior is 6 px right and 4 px up of the regular grid, tiles vary by up to 3 px more.
  EXPECT_GT(row->max_prior_shift_px, 3.0);
  EXPECT_LT(row->max_prior_shift_px, 7.2 + 3 * std::sqrt(2.0) + 1);
  std::printf("%s", FormatLatticeRows({*row}).c_str());
}

TEST(LatticeDetectionTest, APriorTheFrameDoesNotShowIsRefused) {
  const SimLatticeCase c = Case("sim 3x3 regular");
  StatusOr<SimLatticeFrame> frame = RenderSimLatticeFrame(StillLife(), c, 5);
  ASSERT_TRUE(frame.ok()) << frame.status().message();
  // A 5x4 prior on a 3x3 frame of the same size.
  LatticeLayout prior = frame->truth;
  SimCameraSpec other = SimCameraSpec::Integral5x4();
  other.gap_px = 20;
  other.tile_width = (prior.sensor_width - 6 * other.gap_px) / 5;
  other.tile_height = (prior.sensor_height - 5 * other.gap_px) / 4;
  prior = other.Layout();
  prior.sensor_width = frame->truth.sensor_width;
  prior.sensor_height = frame->truth.sensor_height;
  StatusOr<LatticeDetection> detection = DetectLattice(frame->bgr, LatticeOptions(), &prior);
  ASSERT_FALSE(detection.ok()) << detection->report.Summary();
  EXPECT_NE(detection.status().message().find("prior"), std::string::npos) << detection.status().message();
}

TEST(LatticeDetectionTest, BlankFrameIsRefused) {
  const cv::Mat blank(480, 640, CV_8UC3, cv::Scalar::all(128));
  StatusOr<LatticeDetection> detection = DetectLattice(blank, LatticeOptions());
  ASSERT_FALSE(detection.ok());
  EXPECT_EQ(detection.status().code(), StatusCode::kNotFound);
  EXPECT_NE(detection.status().message().find("blank"), std::string::npos) << detection.status().message();
}

TEST(LatticeDetectionTest, PlainPhotoIsRefused) {
  // One lens's clean render: a whole photo with no lattice in it.
  const SimLatticeCase c = Case("sim 3x3 regular");
  StatusOr<std::vector<sim::ViewTruth>> views = sim::RenderLatticeViews(StillLife(), c.spec);
  ASSERT_TRUE(views.ok()) << views.status().message();
  StatusOr<LatticeDetection> detection = DetectLattice((*views)[4].bgr, LatticeOptions());
  ASSERT_FALSE(detection.ok()) << detection->report.Summary();
  EXPECT_EQ(detection.status().code(), StatusCode::kNotFound);
  EXPECT_NE(detection.status().message().find("no lattice"), std::string::npos) << detection.status().message();
  std::printf("plain photo: %s\n", detection.status().message().c_str());
}

TEST(LatticeDetectionTest, WrongFrameTypeIsAnInvalidArgument) {
  const cv::Mat floats(480, 640, CV_32FC3, cv::Scalar::all(0.5));
  StatusOr<LatticeDetection> detection = DetectLattice(floats, LatticeOptions());
  ASSERT_FALSE(detection.ok());
  EXPECT_EQ(detection.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(detection.status().message().find("8-bit"), std::string::npos) << detection.status().message();
}

TEST(LatticeDetectionTest, RealActionSamplerScanIsA2x2WithUprightSplit) {
  StatusOr<cv::Mat> frame = LoadActionSamplerFrame(sim::SharedDataDir());
  if (!frame.ok())
    GTEST_SKIP() << "needs ../shared/data/lattice_frames/actionsampler_2x2_face: " << frame.status().message();
  ASSERT_EQ(frame->cols, 1536);  // raw pixels, not EXIF-rotated (same size either way for 180)
  StatusOr<LatticeDetection> detection = DetectLattice(*frame, LatticeOptions());
  ASSERT_TRUE(detection.ok()) << detection.status().message();
  EXPECT_EQ(detection->report.rows, 2);
  EXPECT_EQ(detection->report.cols, 2);
  // Four quadrant-sized tiles: each at least 60 % of a quadrant on each side.
  for (const Tile& t : detection->layout.tiles) {
    EXPECT_GT(t.rect.width, 0.6 * 768) << t.row << "," << t.col;
    EXPECT_GT(t.rect.height, 0.6 * 512) << t.row << "," << t.col;
    EXPECT_LT(std::abs(t.rotation_deg), 3.0);
  }
  std::printf("ActionSampler: %s\n", detection->report.Summary().c_str());
  for (const Tile& t : detection->layout.tiles) {
    std::printf("  tile (%d,%d): %dx%d at (%d,%d), %.2f deg\n",
                t.row,
                t.col,
                t.rect.width,
                t.rect.height,
                t.rect.x,
                t.rect.y,
                t.rotation_deg);
  }
}

// A real frame of ../shared/data/lattice_frames, its pixels as stored (EXIF orientation ignored).
cv::Mat RealFrame(const std::string& relative) {
  return cv::imread((sim::SharedDataDir() / "lattice_frames" / relative).string(),
                    cv::IMREAD_COLOR | cv::IMREAD_IGNORE_ORIENTATION);
}

// A Sony a6000 behind a three-lens wiggle lens: three heavily vignetted sub-images that touch, no
// gap between them, and a dark lawn and path across every one of them that pass for row gaps.
TEST(LatticeDetectionTest, RealWiggleLensFrameIsThreeAbuttingViews) {
  const cv::Mat frame = RealFrame("wigglelens_3view_plants/plants.jpg");
  if (frame.empty()) GTEST_SKIP() << "needs ../shared/data/lattice_frames/wigglelens_3view_plants";
  StatusOr<LatticeDetection> detection = DetectLattice(frame, LatticeOptions());
  ASSERT_TRUE(detection.ok()) << detection.status().message();
  std::printf("wiggle lens: %s\n", detection->report.Summary().c_str());
  EXPECT_EQ(detection->report.rows, 1);
  EXPECT_EQ(detection->report.cols, 3);
  EXPECT_GE(detection->report.tile_agreement, lattice::kSameSceneAgreement);
  // Each sub-image's dark falloff is trimmed: the outer twentieth of the tiles on either side,
  // about a fifth as bright as their whole in the even cut, is over half as bright after the trim.
  cv::Mat grey;
  cv::cvtColor(frame, grey, cv::COLOR_BGR2GRAY);
  const auto rim_share = [&grey](const cv::Rect& tile) {
    const int rim = tile.width / 20;
    const double rims = (cv::mean(grey(cv::Rect(tile.x, tile.y, rim, tile.height)))[0] +
                         cv::mean(grey(cv::Rect(tile.br().x - rim, tile.y, rim, tile.height)))[0]) /
                        2;
    return rims / cv::mean(grey(tile))[0];
  };
  for (int c = 0; c < 3; ++c) {
    const cv::Rect tile = detection->report.tiles[c].rect;
    const cv::Rect even(c * frame.cols / 3, 0, frame.cols / 3, frame.rows);
    std::printf("tile %d: %dx%d at x %d; its rims at %.2f of its mean, the even cut's at %.2f\n",
                c,
                tile.width,
                tile.height,
                tile.x,
                rim_share(tile),
                rim_share(even));
    EXPECT_EQ(tile.size(), detection->report.tiles[0].rect.size());
    EXPECT_LT(tile.width, even.width * 0.9);
    EXPECT_GE(tile.width, even.width * 0.6);
    EXPECT_GT(rim_share(tile), 0.5);
    EXPECT_LT(rim_share(even), 0.3);
  }
}

// A Nishika N8000 scan: four frames on dark film, each exposed its own way.
TEST(LatticeDetectionTest, RealNishikaScanIsAStripOfFour) {
  const cv::Mat frame = RealFrame("nishika_n8000_scan_1x4/img_small.jpg");
  if (frame.empty()) GTEST_SKIP() << "needs ../shared/data/lattice_frames/nishika_n8000_scan_1x4";
  StatusOr<LatticeDetection> detection = DetectLattice(frame, LatticeOptions());
  ASSERT_TRUE(detection.ok()) << detection.status().message();
  std::printf("Nishika: %s\n", detection->report.Summary().c_str());
  EXPECT_EQ(detection->report.rows, 1);
  EXPECT_EQ(detection->report.cols, 4);
  EXPECT_GE(detection->report.tile_agreement, lattice::kSameSceneAgreement);
}

// Real single photos (../shared/data: the hand-held sets, the stereo face pair, LLFF, the labelled
// face photos, Middlebury, a Lytro view): no cut of one into equal tiles shows one scene, and none
// is taken for a lattice. Prints the best agreement of any cut, the figure the threshold is set by.
TEST(LatticeDetectionTest, RealSinglePhotosAreNotCutIntoViews) {
  const fs::path data = sim::SharedDataDir();
  std::vector<fs::path> photos;
  for (const char* folder : {"handheld/kpankov_office_4views",
                             "handheld/kpankov_frenchpress_4views",
                             "handheld/ddd_lego_excavator_3views",
                             "handheld/ddd_seattle_portrait_2views",
                             "stereo_face/ddd_frame31_stereo",
                             "faces_dlib_pascalvoc"}) {
    std::error_code error;
    for (const auto& entry : fs::directory_iterator(data / folder, error)) photos.push_back(entry.path());
  }
  for (const char* file : {"llff_fern/images_8/image000.png",
                           "llff_flower/images_8/image000.png",
                           "middlebury_2006_thirdsize/Aloe/view1.png",
                           "middlebury_2006_thirdsize/Baby1/view1.png",
                           "middlebury_2006_thirdsize/Bowling1/view1.png",
                           "lytro_illum_2067_center5x5/2067_03_03.png"}) {
    photos.push_back(data / file);
  }
  double best = -1;
  int read = 0;
  for (const fs::path& file : photos) {
    const cv::Mat photo = cv::imread(file.string(), cv::IMREAD_COLOR);
    if (photo.empty()) continue;
    ++read;
    cv::Mat grey;
    cv::cvtColor(photo, grey, cv::COLOR_BGR2GRAY);
    const LatticeOptions options;
    const lattice::EqualCut cut = lattice::FindEqualCut(lattice::CoarseWorkingFrame(grey, options.working_size_px),
                                                        cv::Size(1, 1),
                                                        options.max_tiles_per_axis,
                                                        0,
                                                        0,
                                                        true);
    EXPECT_EQ(cut.rows, 0) << file << ": " << cut.cols << "x" << cut.rows << " agrees " << cut.agreement;
    best = std::max(best, cut.agreement);
    StatusOr<LatticeDetection> detection = DetectLattice(photo, options);
    EXPECT_FALSE(detection.ok()) << file << ": " << detection->report.Summary();
  }
  if (read == 0) GTEST_SKIP() << "needs the real photos under " << data.string();
  std::printf(
      "%d real single photos: best agreement of any cut into equal tiles (up to 8 per axis) %.2f\n", read, best);
}

TEST(LatticeDetectionTest, RaytrixMicroLensImageIsRefusedWithAReason) {
  const auto file = sim::SharedDataDir() / "lattice_frames" / "raytrix_r42_lenslet_crop" / "sc2_klein.png";
  const std::vector<LatticeEvalRow> rows = EvaluateRealLatticeFrames(sim::SharedDataDir());
  const LatticeEvalRow* raytrix = nullptr;
  for (const LatticeEvalRow& row : rows) {
    if (row.name.find("Raytrix") != std::string::npos) raytrix = &row;
  }
  if (raytrix == nullptr) GTEST_SKIP() << "needs " << file.string();
  std::printf("%s", FormatLatticeRows(rows).c_str());
  EXPECT_FALSE(raytrix->found) << raytrix->summary;
  EXPECT_FALSE(raytrix->error.empty());
}

}  // namespace
}  // namespace px::eval
