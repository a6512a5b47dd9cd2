// How well lattice detection (pipeline/lattice) finds the tile grid: on simulated frames whose
// true layout is known (regular, and with unequal, offset and slightly turned tiles, lens
// distortion and vignetting) and on the real ActionSampler film scan in ../shared/data.
// `parallax eval calib` prints these rows; the lattice tests run a few of them.
#pragma once

#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "pipeline/core/lattice_layout.h"
#include "pipeline/core/status.h"
#include "pipeline/lattice/lattice_detector.h"
#include "sim/synthetic/lattice_variation.h"
#include "sim/synthetic/scene.h"
#include "sim/synthetic/sim_camera.h"

namespace px::eval {

// How far each detected tile's four (turned) corners lie from the truth's, pixels.
struct LayoutError {
  double mean_corner_px = 0;
  double max_corner_px = 0;
  double max_rotation_deg = 0;  // |detected - true| tile rotation, largest over the tiles
};

// INVALID_ARGUMENT when the two layouts differ in rows x cols.
StatusOr<LayoutError> CompareLayouts(const LatticeLayout& truth, const LatticeLayout& found);

struct SimLatticeCase {
  std::string name;
  SimCameraSpec spec;
  sim::LatticeVariation variation;  // none: the spec's regular layout
  bool use_prior = false;           // detect near a prior: the regular layout, shifted by prior_shift_px
  cv::Point2i prior_shift_px{0, 0};
};

// The cases `parallax eval calib` reports: 2x2, 3x3 (Pop9) and 5x4 (integral) lattices, regular
// and varied (offset up to 3 px, sizes +-2 %, turned up to 1 deg), with distortion and vignetting;
// and detection near a prior that is 6 px off. Tiles are at `scale` of the presets' size
// (1 = full size; the tests use 0.5).
std::vector<SimLatticeCase> StandardSimLatticeCases(double scale = 1.0);

struct LatticeEvalRow {
  std::string name;
  bool found = false;
  std::string error;  // why not, when !found
  int rows = 0;
  int cols = 0;
  bool has_truth = false;  // simulated cases: layout_error is set
  LayoutError layout_error;
  double confidence = 0;
  double tile_agreement = -1;  // LatticeReport::tile_agreement (blind search only)
  double max_prior_shift_px = 0;
  double ms = 0;        // detection time (the render is not counted)
  std::string summary;  // LatticeReport::Summary()
};

// The simulated sensor frame of one case and its true layout (rendered from `scene`).
struct SimLatticeFrame {
  cv::Mat bgr;
  LatticeLayout truth;
};
StatusOr<SimLatticeFrame> RenderSimLatticeFrame(const sim::Scene& scene, const SimLatticeCase& c, uint64_t seed);

// Renders the case, detects the lattice and compares with the truth. A detection failure is a
// row with found = false (an error only when the case cannot be rendered).
StatusOr<LatticeEvalRow> EvaluateSimLatticeCase(const sim::Scene& scene, const SimLatticeCase& c, uint64_t seed);

// The ActionSampler scan's raw pixels, as the film lies in the scanner: loaded with its EXIF
// orientation (3: rotate 180 to view) deliberately ignored, so the four tiles are each inverted as
// the lenses put them on the film. NOT_FOUND naming the file when absent.
StatusOr<cv::Mat> LoadActionSamplerFrame(const std::filesystem::path& data_dir);

// Detection on the real frames in data_dir/lattice_frames: the ActionSampler 2x2 scan (no ground
// truth: figures are the tile sizes, rotations and confidence) and the Raytrix micro-lens crop
// (expected to be refused, with the reason). Rows for files that are absent are left out.
std::vector<LatticeEvalRow> EvaluateRealLatticeFrames(const std::filesystem::path& data_dir);

// Rows in one table, one line each.
std::string FormatLatticeRows(const std::vector<LatticeEvalRow>& rows);

}  // namespace px::eval
