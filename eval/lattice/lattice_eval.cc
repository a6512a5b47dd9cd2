#include "eval/lattice/lattice_eval.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "sim/synthetic/sim_sensor.h"

namespace px::eval {
namespace {

SimCameraSpec Scaled(SimCameraSpec spec, double scale) {
  spec.tile_width = static_cast<int>(std::lround(spec.tile_width * scale));
  spec.tile_height = static_cast<int>(std::lround(spec.tile_height * scale));
  spec.focal_px *= scale;
  spec.supersampling = 1;
  return spec;
}

// What real lattice sensors show: barrel distortion, vignetting, per-lens exposure, noise.
SimCameraSpec WithDefects(SimCameraSpec spec) {
  spec.distortion = {-0.12, 0.03, 0, 0, 0};
  spec.vignetting = 0.35;
  spec.exposure_spread = 0.1;
  spec.noise_sigma = 2.0;
  return spec;
}

SimCameraSpec TwoByTwo() {
  SimCameraSpec spec = SimCameraSpec::Pop9();
  spec.name = "sim-2x2";
  spec.rows = 2;
  spec.cols = 2;
  return spec;
}

sim::LatticeVariation Varied(uint64_t seed) {
  sim::LatticeVariation v;
  v.max_offset_px = 3;
  v.max_size_change = 0.02;
  v.max_rotation_deg = 1.0;
  v.outer_margin_px = 24;
  v.seed = seed;
  return v;
}

std::string Fixed(double value, int digits) {
  char text[64];
  std::snprintf(text, sizeof(text), "%.*f", digits, value);
  return text;
}

}  // namespace

StatusOr<LayoutError> CompareLayouts(const LatticeLayout& truth, const LatticeLayout& found) {
  if (truth.rows != found.rows || truth.cols != found.cols) {
    return InvalidArgumentError("lattice comparison: found " + std::to_string(found.cols) + "x" +
                                std::to_string(found.rows) + " tiles, the truth has " + std::to_string(truth.cols) +
                                "x" + std::to_string(truth.rows));
  }
  LayoutError error;
  double sum = 0;
  for (size_t i = 0; i < truth.tiles.size(); ++i) {
    const std::array<cv::Point2d, 4> t = TileCorners(truth.tiles[i]), f = TileCorners(found.tiles[i]);
    for (int k = 0; k < 4; ++k) {
      const double d = cv::norm(t[k] - f[k]);
      sum += d;
      error.max_corner_px = std::max(error.max_corner_px, d);
    }
    error.max_rotation_deg =
        std::max(error.max_rotation_deg, std::abs(truth.tiles[i].rotation_deg - found.tiles[i].rotation_deg));
  }
  error.mean_corner_px = truth.tiles.empty() ? 0 : sum / (4.0 * truth.tiles.size());
  return error;
}

std::vector<SimLatticeCase> StandardSimLatticeCases(double scale) {
  std::vector<SimLatticeCase> cases;
  const std::vector<std::pair<std::string, SimCameraSpec>> specs = {
      {"2x2", TwoByTwo()}, {"3x3", SimCameraSpec::Pop9()}, {"5x4", SimCameraSpec::Integral5x4()}};
  uint64_t seed = 11;
  for (const auto& [name, preset] : specs) {
    SimCameraSpec spec = WithDefects(Scaled(preset, scale));
    // Room for tiles turned by 1 degree and offset by 3 px (a 640 px tile's corner moves 5.6 px).
    spec.gap_px = std::max({spec.gap_px, 16, static_cast<int>(std::lround(24 * scale))});
    cases.push_back({"sim " + name + " regular", spec, {}, false, {0, 0}});
    cases.push_back({"sim " + name + " varied", spec, Varied(seed++), false, {0, 0}});
  }
  cases.push_back({"sim 3x3 varied, prior 7 px off", cases[3].spec, cases[3].variation, true, {6, -4}});
  return cases;
}

StatusOr<SimLatticeFrame> RenderSimLatticeFrame(const sim::Scene& scene, const SimLatticeCase& c, uint64_t seed) {
  PX_ASSIGN_OR_RETURN(std::vector<sim::ViewTruth> views, sim::RenderLatticeViews(scene, c.spec));
  const std::vector<double> gains = sim::DrawExposureGains(c.spec, seed);
  const uint64_t noise_seed = sim::CaptureNoiseSeed(seed, 0);
  SimLatticeFrame frame;
  const bool varied = c.variation.max_offset_px > 0 || c.variation.max_size_change > 0 ||
                      c.variation.max_rotation_deg > 0 || c.variation.outer_margin_px >= 0;
  if (!varied) {
    frame.truth = c.spec.Layout();
    frame.bgr = sim::ComposeSensorBgr(c.spec, views, gains, noise_seed);
    return frame;
  }
  PX_ASSIGN_OR_RETURN(frame.truth, sim::VariedLayout(c.spec, c.variation));
  frame.bgr = sim::ComposeSensorOnLayout(c.spec, frame.truth, views, gains, noise_seed);
  return frame;
}

StatusOr<LatticeEvalRow> EvaluateSimLatticeCase(const sim::Scene& scene, const SimLatticeCase& c, uint64_t seed) {
  PX_ASSIGN_OR_RETURN(SimLatticeFrame frame, RenderSimLatticeFrame(scene, c, seed));
  LatticeEvalRow row;
  row.name = c.name;
  LatticeOptions options;
  LatticeLayout prior;
  if (c.use_prior) {
    // The regular layout of the same sensor, moved: what a factory calibration gives after a knock.
    prior = c.spec.Layout();
    prior.sensor_width = frame.truth.sensor_width;
    prior.sensor_height = frame.truth.sensor_height;
    const int margin = (frame.truth.sensor_width - c.spec.Layout().sensor_width) / 2;
    for (Tile& tile : prior.tiles) tile.rect += cv::Point(margin, margin) + c.prior_shift_px;
  }
  StatusOr<LatticeDetection> detection = DetectLattice(frame.bgr, options, c.use_prior ? &prior : nullptr);
  if (!detection.ok()) {
    row.error = detection.status().message();
    return row;
  }
  row.found = true;
  row.rows = detection->report.rows;
  row.cols = detection->report.cols;
  row.confidence = detection->report.confidence;
  row.tile_agreement = detection->report.tile_agreement;
  row.max_prior_shift_px = detection->report.max_prior_shift_px;
  row.ms = detection->report.ms;
  row.summary = detection->report.Summary();
  StatusOr<LayoutError> error = CompareLayouts(frame.truth, detection->layout);
  if (!error.ok()) {
    row.found = false;
    row.error = error.status().message();
    return row;
  }
  row.has_truth = true;
  row.layout_error = *error;
  return row;
}

StatusOr<cv::Mat> LoadActionSamplerFrame(const std::filesystem::path& data_dir) {
  const std::filesystem::path file = data_dir / "lattice_frames" / "actionsampler_2x2_face" / "imm000_0.jpg";
  // IMREAD_IGNORE_ORIENTATION: the sensor (film) pixels, not the EXIF-rotated view.
  cv::Mat bgr = cv::imread(file.string(), cv::IMREAD_COLOR | cv::IMREAD_IGNORE_ORIENTATION);
  if (bgr.empty()) return NotFoundError("ActionSampler frame: cannot read " + file.string());
  return bgr;
}

std::vector<LatticeEvalRow> EvaluateRealLatticeFrames(const std::filesystem::path& data_dir) {
  std::vector<LatticeEvalRow> rows;
  auto detect = [&](const std::string& name, const cv::Mat& bgr) {
    LatticeEvalRow row;
    row.name = name;
    StatusOr<LatticeDetection> detection = DetectLattice(bgr, LatticeOptions());
    if (detection.ok()) {
      row.found = true;
      row.rows = detection->report.rows;
      row.cols = detection->report.cols;
      row.confidence = detection->report.confidence;
      row.tile_agreement = detection->report.tile_agreement;
      row.ms = detection->report.ms;
      row.summary = detection->report.Summary();
    } else {
      row.error = detection.status().message();
    }
    rows.push_back(row);
  };
  if (StatusOr<cv::Mat> frame = LoadActionSamplerFrame(data_dir); frame.ok()) detect("ActionSampler 2x2 scan", *frame);
  const std::filesystem::path raytrix = data_dir / "lattice_frames" / "raytrix_r42_lenslet_crop" / "sc2_klein.png";
  if (cv::Mat bgr = cv::imread(raytrix.string(), cv::IMREAD_COLOR); !bgr.empty()) {
    detect("Raytrix micro-lens crop", bgr);
  }
  return rows;
}

std::string FormatLatticeRows(const std::vector<LatticeEvalRow>& rows) {
  std::ostringstream out;
  for (const LatticeEvalRow& row : rows) {
    out << row.name << ": ";
    if (!row.found) {
      out << "refused: " << row.error << "\n";
      continue;
    }
    out << row.cols << "x" << row.rows;
    if (row.has_truth) {
      out << ", corner error mean " << Fixed(row.layout_error.mean_corner_px, 2) << " px, max "
          << Fixed(row.layout_error.max_corner_px, 2) << " px, rotation error max "
          << Fixed(row.layout_error.max_rotation_deg, 2) << " deg";
    }
    if (row.max_prior_shift_px > 0) out << ", prior shift up to " << Fixed(row.max_prior_shift_px, 1) << " px";
    out << ", confidence " << Fixed(row.confidence, 2);
    if (row.tile_agreement >= 0) out << ", tiles agree " << Fixed(row.tile_agreement, 2);
    out << ", " << Fixed(row.ms, 0) << " ms";
    if (!row.has_truth) out << " (" << row.summary << ")";
    out << "\n";
  }
  return out.str();
}

}  // namespace px::eval
