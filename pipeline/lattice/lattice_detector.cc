#include "pipeline/lattice/lattice_detector.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "pipeline/core/order_statistics.h"
#include "pipeline/core/stage_clock.h"
#include "pipeline/lattice/axis_grid.h"
#include "pipeline/lattice/boundary_profile.h"
#include "pipeline/lattice/tile_agreement.h"
#include "pipeline/lattice/tile_edge_fit.h"
#include "pipeline/lattice/tile_geometry.h"
#include "pipeline/lattice/vignette_trim.h"

namespace px {
namespace {

using lattice::AxisGrid;
using lattice::BoundaryProfile;
using lattice::EdgeFit;
using lattice::EdgeLine;
using lattice::EdgeSearch;
using lattice::TileEdges;
using lattice::TileGeometry;

// A frame whose grey levels vary less than this (standard deviation) shows nothing at all.
constexpr double kBlankStddev = 1.0;
// Edge cuts stay this fraction of the tile's length away from its corners (rounded corners,
// the neighbouring gap's own edges).
constexpr double kCornerMargin = 0.12;
// Beyond the allowed tilt, fitted edges are trusted this much more before a tile is refused.
constexpr double kRotationToleranceDeg = 1.0;
// Near a prior, at least this fraction of the tile edges inside the frame must be found.
constexpr double kMinPriorEdgesFound = 0.8;
// A lens's view is at most this many times longer than wide; a tile found longer holds several.
constexpr double kMaxViewAspect = 2.0;
// A margin at the frame's border is at most this fraction of a tile long.
constexpr double kMaxMarginOfPeriod = 0.2;

std::string Format(const char* format, double a, double b = 0, double c = 0, double d = 0) {
  char text[256];
  std::snprintf(text, sizeof(text), format, a, b, c, d);
  return text;
}

// The full-resolution grey frame (8-bit: large float copies cost more in page faults than the
// whole search).
struct GreyFrame {
  cv::Mat grey;  // CV_8UC1
  double mean = 0;
  double stddev = 0;
};

GreyFrame MakeGrey(const cv::Mat& frame) {
  GreyFrame g;
  if (frame.channels() == 3) {
    cv::cvtColor(frame, g.grey, cv::COLOR_BGR2GRAY);
  } else {
    g.grey = frame;
  }
  cv::Scalar mean, stddev;
  cv::meanStdDev(g.grey, mean, stddev);
  g.mean = mean[0];
  g.stddev = stddev[0];
  return g;
}

// One boundary between tiles along an axis, in sensor pixels.
struct Boundary {
  double centre = 0;        // gap centre; for an outer boundary, where the margin ends (or the frame edge)
  double half_width = 0;    // estimated half-width of the gap band
  int polarity = 0;         // -1 dark band, +1 bright band, 0 unknown
  bool frame_edge = false;  // the tiles run to the frame's border here: nothing to fit
  double z = 0;
};

// Tiles along one axis: count + 1 boundaries (outer, internal..., outer).
struct AxisPlan {
  int count = 1;
  std::vector<Boundary> boundaries;
  double shear = 0;  // expected slope of the edges (a tilted frame)
  double gap_level = 0;
  double tile_level = 0;
};

// Working pixel i covers sensor [i s, (i + 1) s): its centre lies at (i + 0.5) s - 0.5.
double ToSensor(double working, double s) { return (working + 0.5) * s - 0.5; }

// The outer boundary at the start (from_start) or end of the axis: a margin as gap-like as the
// internal gaps ends where the tiles begin; otherwise the tiles run to the frame's border.
Boundary OuterBoundary(const BoundaryProfile& profile,
                       double gap_level,
                       double tile_level,
                       double period,
                       bool from_start,
                       double s,
                       int sensor_size) {
  Boundary b;
  const int size = profile.size();
  const double contrast = std::abs(tile_level - gap_level);
  int margin = 0;
  if (contrast > 10) {
    const int limit = static_cast<int>(kMaxMarginOfPeriod * period);
    while (margin < limit) {
      const int x = from_start ? margin : size - 1 - margin;
      if (std::abs(profile.level[x] - gap_level) > 0.4 * contrast) break;
      ++margin;
    }
    if (margin >= limit) margin = 0;  // no tile where one should start: not a margin
  }
  if (margin <= 1) {
    b.frame_edge = true;
    b.centre = from_start ? -0.5 : sensor_size - 0.5;
    return b;
  }
  b.centre = from_start ? margin * s - 0.5 : sensor_size - margin * s - 0.5;
  b.polarity = gap_level < tile_level ? -1 : 1;
  return b;
}

AxisPlan PlanAxis(const BoundaryProfile& profile,
                  const AxisGrid& grid,
                  double gap_level,
                  double tile_level,
                  double s,
                  int sensor_size) {
  AxisPlan plan;
  plan.count = grid.count;
  plan.shear = profile.shear;
  plan.gap_level = gap_level;
  plan.tile_level = tile_level;
  const double period = static_cast<double>(profile.size()) / grid.count;
  plan.boundaries.push_back(OuterBoundary(profile, gap_level, tile_level, period, true, s, sensor_size));
  for (size_t k = 0; k < grid.gaps.size(); ++k) {
    Boundary b;
    b.centre = ToSensor(grid.gaps[k], s);
    b.half_width = grid.gap_half_width[k] * s;
    b.polarity = grid.gap_polarity[k];
    b.z = grid.gap_z[k];
    plan.boundaries.push_back(b);
  }
  plan.boundaries.push_back(OuterBoundary(profile, gap_level, tile_level, period, false, s, sensor_size));
  return plan;
}

// Where tile k's coarse extent along the axis starts and ends.
double CoarseStart(const AxisPlan& plan, int k) {
  const Boundary& b = plan.boundaries[k];
  return b.centre + b.half_width;
}
double CoarseEnd(const AxisPlan& plan, int k) {
  const Boundary& b = plan.boundaries[k + 1];
  return b.centre - b.half_width;
}

struct EdgeResult {
  EdgeFit fit;
  bool fixed = false;  // on the frame's border
  EdgeLine line;       // the line used (fitted, fixed or fallback)
};

// Fits the edge where tile k starts (start = true: its left/top) or ends, along one axis.
EdgeResult FitPlannedEdge(const cv::Mat& grey,
                          bool transposed,
                          const AxisPlan& plan,
                          int k,
                          bool start,
                          double along_begin,
                          double along_end,
                          double max_slope) {
  EdgeResult result;
  const Boundary& b = plan.boundaries[start ? k : k + 1];
  if (b.frame_edge) {
    result.fixed = true;
    result.line = {b.centre, 0.0};
    return result;
  }
  const double length = along_end - along_begin;
  const double drift = max_slope * length * 0.5;
  const double uncertainty = 4.0 + drift;
  const bool outer = (start && k == 0) || (!start && k + 1 == plan.count);
  EdgeSearch search;
  search.transposed = transposed;
  search.along_begin = along_begin + kCornerMargin * length;
  search.along_end = along_end - kCornerMargin * length;
  search.max_slope = max_slope;
  search.expected = {b.centre - plan.shear * 0.5 * (along_begin + along_end), plan.shear};
  const double into_tile = outer ? uncertainty : 1.5 * b.half_width + uncertainty;
  search.behind_px = start ? uncertainty : into_tile;
  search.ahead_px = start ? into_tile : uncertainty;
  // Leaving a dark band into a tile, brightness rises: the start edge of the next tile rises, the
  // end edge of the previous one falls (the reverse for a bright band).
  search.sign = start ? -b.polarity : b.polarity;
  // Dark gaps (a sensor mask) are clean: the tile starts at the first strong transition out of
  // them. Bright, irregular borders (film scans) hold transitions of their own: take the strongest.
  search.gap_side = b.polarity < 0 ? (start ? -1 : 1) : 0;
  result.fit = lattice::FitEdge(grey, search);
  if (!result.fit.found && search.sign != 0) {
    search.sign = 0;  // a plain step between touching tiles has one sign for both of them
    result.fit = lattice::FitEdge(grey, search);
  }
  result.line =
      result.fit.found
          ? result.fit.line
          : EdgeLine{(start ? CoarseStart(plan, k) : CoarseEnd(plan, k)) - plan.shear * 0.5 * (along_begin + along_end),
                     plan.shear};
  return result;
}

struct TileFits {
  std::array<EdgeResult, 4> edges;
};

// Builds the report's tile and the geometry from four edge results.
DetectedTile AssembleTile(int row, int col, const TileFits& fits, TileGeometry* geometry) {
  TileEdges edges;
  DetectedTile tile;
  tile.row = row;
  tile.col = col;
  double inlier_sum = 0, rms_sum = 0;
  int searched = 0, fitted_searched = 0;
  for (int side = 0; side < 4; ++side) {
    const EdgeResult& e = fits.edges[side];
    edges.lines[side] = e.line;
    if (e.fixed) {
      ++tile.edges_fitted;
      continue;
    }
    ++searched;
    inlier_sum += e.fit.InlierFraction();
    if (e.fit.found) {
      ++tile.edges_fitted;
      ++fitted_searched;
      rms_sum += e.fit.rms_px;
      edges.angle_weight[side] = e.fit.inliers;
    }
  }
  tile.inlier_fraction = searched > 0 ? inlier_sum / searched : 1.0;
  tile.edge_rms_px = fitted_searched > 0 ? rms_sum / fitted_searched : 0.0;
  *geometry = lattice::GeometryFromEdges(edges);
  tile.rect = geometry->Rect();
  tile.rotation_deg = geometry->rotation_deg;
  return tile;
}

// An internal edge that was not found takes its position from the tile across the gap (whose
// edge was found) and the gap widths measured where both sides were found.
void FillFromAcrossTheGap(std::vector<TileFits>* fits, int rows, int cols) {
  std::array<std::vector<double>, 2> widths;  // [0]: vertical gaps, [1]: horizontal
  auto gap_pairs = [&](auto&& visit) {
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c + 1 < cols; ++c)
        visit(0, (*fits)[r * cols + c].edges[lattice::kRight], (*fits)[r * cols + c + 1].edges[lattice::kLeft]);
    }
    for (int r = 0; r + 1 < rows; ++r) {
      for (int c = 0; c < cols; ++c)
        visit(1, (*fits)[r * cols + c].edges[lattice::kBottom], (*fits)[(r + 1) * cols + c].edges[lattice::kTop]);
    }
  };
  gap_pairs([&](int axis, EdgeResult& end, EdgeResult& start) {
    if (end.fit.found && start.fit.found) widths[axis].push_back(start.line.a - end.line.a);
  });
  gap_pairs([&](int axis, EdgeResult& end, EdgeResult& start) {
    if (widths[axis].empty() || end.fit.found == start.fit.found) return;
    const double width = Median(widths[axis]);
    if (end.fit.found) {
      start.line = {end.line.a + width, end.line.b};
    } else {
      end.line = {start.line.a - width, start.line.b};
    }
  });
}

std::string TileName(int row, int col) { return "tile (" + std::to_string(row) + "," + std::to_string(col) + ")"; }

// Sizes within the allowed spread of the median and tilts within the allowed range.
Status CheckTiles(const std::vector<DetectedTile>& tiles, const LatticeOptions& options) {
  std::vector<double> widths, heights;
  for (const DetectedTile& t : tiles) {
    widths.push_back(t.rect.width);
    heights.push_back(t.rect.height);
  }
  const double median_w = Median(widths), median_h = Median(heights);
  for (const DetectedTile& t : tiles) {
    if (std::abs(t.rect.width / median_w - 1) > options.max_size_spread ||
        std::abs(t.rect.height / median_h - 1) > options.max_size_spread || t.rect.width < 8 || t.rect.height < 8) {
      return NotFoundError("no lattice: tiles of wildly different sizes: " + TileName(t.row, t.col) + " is " +
                           std::to_string(t.rect.width) + "x" + std::to_string(t.rect.height) +
                           " px against a median of " + Format("%.0fx%.0f", median_w, median_h) + " (more than " +
                           Format("%.0f", 100 * options.max_size_spread) + "% off)");
    }
    if (std::abs(t.rotation_deg) > options.max_rotation_deg + kRotationToleranceDeg) {
      return NotFoundError(
          "no lattice: " + TileName(t.row, t.col) + "'s edges fit a rotation of " +
          Format("%.1f deg, more than the %.1f deg allowed", t.rotation_deg, options.max_rotation_deg));
    }
  }
  return OkStatus();
}

// Figures that say what told the tiles apart.
std::vector<std::string> Evidence(const GreyFrame& frame,
                                  const LatticeLayout& layout,
                                  const AxisPlan* x,
                                  const AxisPlan* y,
                                  const std::vector<DetectedTile>& tiles) {
  std::vector<std::string> evidence;
  const AxisPlan* plan = x != nullptr && x->count > 1 ? x : y;
  if (plan != nullptr) {
    int dark = 0, bright = 0;
    for (const AxisPlan* p : {x, y}) {
      for (size_t k = 1; k + 1 < p->boundaries.size(); ++k) (p->boundaries[k].polarity < 0 ? dark : bright)++;
    }
    const double contrast = plan->tile_level - plan->gap_level;
    if (std::abs(contrast) < 10) {
      evidence.push_back(
          Format("tile edges without a distinct gap (gap grey %.0f, tiles %.0f)", plan->gap_level, plan->tile_level));
    } else {
      evidence.push_back(Format(dark >= bright ? "dark gaps (grey %.0f against %.0f in the tiles)"
                                               : "bright gaps (grey %.0f against %.0f in the tiles)",
                                plan->gap_level,
                                plan->tile_level));
    }
  }
  int fitted = 0, searched = 0;
  double rms = 0;
  for (const DetectedTile& t : tiles) {
    fitted += t.edges_fitted;
    searched += 4;
    rms += t.edge_rms_px;
  }
  evidence.push_back(Format("tile edges: %.0f of %.0f fitted as lines, %.2f px RMS",
                            fitted,
                            searched,
                            rms / std::max<size_t>(1, tiles.size())));
  // Vignetting: brightness of a ring near each tile's border against its centre.
  std::vector<double> ratios;
  for (const Tile& tile : layout.tiles) {
    const cv::Rect r = tile.rect;
    const cv::Rect inner(r.x + r.width / 4, r.y + r.height / 4, r.width / 2, r.height / 2);
    const cv::Rect ring_outer(r.x + r.width / 20, r.y + r.height / 20, r.width * 9 / 10, r.height * 9 / 10);
    const cv::Rect ring_inner(r.x + r.width / 8, r.y + r.height / 8, r.width * 3 / 4, r.height * 3 / 4);
    const cv::Rect frame_rect(0, 0, frame.grey.cols, frame.grey.rows);
    if ((ring_outer & frame_rect) != ring_outer) continue;
    const double sum_outer = cv::sum(frame.grey(ring_outer))[0], sum_inner_ring = cv::sum(frame.grey(ring_inner))[0];
    const double ring = (sum_outer - sum_inner_ring) / (ring_outer.area() - ring_inner.area());
    const double centre = cv::mean(frame.grey(inner))[0];
    if (centre > 5) ratios.push_back(ring / centre);
  }
  const double ratio = Median(ratios);
  if (!ratios.empty() && ratio < 0.9) {
    evidence.push_back(Format("vignetting: tile borders at %.0f%% of the centres' brightness", 100 * ratio));
  }
  return evidence;
}

// The level of the gaps and of the tiles from the coarse profiles (medians along the lines).
void GapAndTileLevels(const BoundaryProfile& px,
                      const AxisGrid& gx,
                      const BoundaryProfile& py,
                      const AxisGrid& gy,
                      double* gap_level,
                      double* tile_level) {
  std::vector<double> gaps, tiles;
  for (const auto& [profile, grid] : {std::pair(&px, &gx), std::pair(&py, &gy)}) {
    std::vector<bool> near_gap(profile->size(), false);
    for (size_t k = 0; k < grid->gaps.size(); ++k) {
      const int at = static_cast<int>(grid->gaps[k]);
      gaps.push_back(profile->level[at]);
      for (int d = -3 * grid->gap_half_width[k]; d <= 3 * grid->gap_half_width[k]; ++d) {
        if (at + d >= 0 && at + d < profile->size()) near_gap[at + d] = true;
      }
    }
    for (int x = 0; x < profile->size(); ++x) {
      if (!near_gap[x]) tiles.push_back(profile->level[x]);
    }
  }
  *gap_level = Median(gaps);
  *tile_level = Median(tiles);
}

Status CheckFrame(const cv::Mat& frame) {
  if (frame.empty()) return InvalidArgumentError("lattice detection: the sensor frame is empty");
  if (frame.type() != CV_8UC3 && frame.type() != CV_8UC1) {
    return InvalidArgumentError("lattice detection: the sensor frame has " + std::to_string(frame.channels()) +
                                " channels of depth " + std::to_string(frame.depth()) +
                                ", want 8-bit BGR or grey (CV_8UC3, CV_8UC1)");
  }
  if (frame.cols < 32 || frame.rows < 32) {
    return InvalidArgumentError("lattice detection: the sensor frame is " + std::to_string(frame.cols) + "x" +
                                std::to_string(frame.rows) + ", too small for a lattice (at least 32x32)");
  }
  return OkStatus();
}

LatticeLayout LayoutFromTiles(const std::vector<DetectedTile>& tiles,
                              int rows,
                              int cols,
                              const cv::Size& size,
                              const std::vector<TileOrientation>& orientations) {
  LatticeLayout layout;
  layout.rows = rows;
  layout.cols = cols;
  layout.sensor_width = size.width;
  layout.sensor_height = size.height;
  for (size_t i = 0; i < tiles.size(); ++i) {
    Tile tile;
    tile.row = tiles[i].row;
    tile.col = tiles[i].col;
    tile.rect = tiles[i].rect;
    tile.rotation_deg = tiles[i].rotation_deg;
    tile.orientation = orientations[i];
    layout.tiles.push_back(tile);
  }
  return layout;
}

struct GridPair {
  AxisGrid x, y;
  double agreement = -1;  // TileAgreement, -1 when not measured
};

// The columns and rows of the lattice. Where the gaps along an axis fit several counts (content
// lines taken for gaps: a dark lawn across every view), the tiles' pictures decide: the most tiles
// whose neighbours show one scene (tile_agreement.h). `evidence` says how, when it came to that.
StatusOr<GridPair> ResolvePeriods(const cv::Mat& work,
                                  const lattice::AxisGrids& grids_x,
                                  const lattice::AxisGrids& grids_y,
                                  std::string* evidence) {
  if (grids_x.ambiguity.empty() && grids_y.ambiguity.empty()) {
    return GridPair{grids_x.candidates.front(), grids_y.candidates.front()};
  }
  struct Tried {
    const AxisGrid* x;
    const AxisGrid* y;
    double agreement;
  };
  std::vector<Tried> tried;
  for (const AxisGrid& x : grids_x.candidates) {
    for (const AxisGrid& y : grids_y.candidates) {
      if (x.count * y.count < 2) continue;
      tried.push_back({&x, &y, lattice::TileAgreement(work, x.gaps, y.gaps)});
    }
  }
  // Most tiles first; among as many, the better agreement.
  std::stable_sort(tried.begin(), tried.end(), [](const Tried& a, const Tried& b) {
    const int ta = a.x->count * a.y->count, tb = b.x->count * b.y->count;
    return ta != tb ? ta > tb : a.agreement > b.agreement;
  });
  std::string figures;
  for (const Tried& t : tried) {
    figures += (figures.empty() ? "" : ", ") + Format("%.0fx%.0f ", t.x->count, t.y->count) +
               (t.agreement == lattice::kTilesTooThin ? std::string("too thin") : Format("%.2f", t.agreement));
  }
  const std::string ambiguity =
      grids_x.ambiguity + (grids_x.ambiguity.empty() || grids_y.ambiguity.empty() ? "" : "; ") + grids_y.ambiguity;
  for (const Tried& t : tried) {
    if (t.agreement < lattice::kSameSceneAgreement) continue;
    *evidence =
        ambiguity +
        Format("; the tiles decide: %.0f columns x %.0f rows show one scene (agreement ", t.x->count, t.y->count) +
        figures + ")";
    return GridPair{*t.x, *t.y, t.agreement};
  }
  return NotFoundError("no lattice: " + ambiguity +
                       Format(", and no such grid's tiles show one scene (agreement of neighbouring tiles, want %.2f: ",
                              lattice::kSameSceneAgreement) +
                       figures + ")");
}

cv::Mat WorkingFrame(const GreyFrame& frame, const LatticeOptions& options) {
  return lattice::CoarseWorkingFrame(frame.grey, options.working_size_px);
}

// Blind search: counts and coarse gaps from the profiles, then every tile's edges. Where the
// gaps cannot give a lattice but the tiles may still abut (no gap crosses the frame, a period no
// count's tiles resolve, tiles that do not agree), `tiles_may_abut` is set: the equal cuts
// (DetectAbutting) may follow. Other refusals (a micro-lens image, tilted or unequal tiles, a low
// confidence) stand.
StatusOr<LatticeDetection> DetectBlind(const GreyFrame& frame, const LatticeOptions& options, bool* tiles_may_abut) {
  *tiles_may_abut = false;
  const int width = frame.grey.cols, height = frame.grey.rows;
  const cv::Mat work = WorkingFrame(frame, options);
  const double s_x = static_cast<double>(width) / work.cols, s_y = static_cast<double>(height) / work.rows;
  cv::Mat work_t;
  cv::transpose(work, work_t);
  // The two axes are independent: one worker each.
  std::array<BoundaryProfile, 2> profiles;
  cv::parallel_for_(cv::Range(0, 2), [&](const cv::Range& range) {
    for (int axis = range.start; axis < range.end; ++axis) {
      profiles[axis] = lattice::VerticalBoundaryProfile(axis == 0 ? work : work_t, options.max_rotation_deg);
    }
  });
  const BoundaryProfile& px = profiles[0];
  const BoundaryProfile& py = profiles[1];

  lattice::AxisSearch search_x{options.cols, options.max_tiles_per_axis, options.min_gap_z, "columns", 'x', s_x};
  lattice::AxisSearch search_y{options.rows, options.max_tiles_per_axis, options.min_gap_z, "rows", 'y', s_y};
  PX_ASSIGN_OR_RETURN(const lattice::AxisGrids grids_x, lattice::FindAxisGrid(px, search_x));
  PX_ASSIGN_OR_RETURN(const lattice::AxisGrids grids_y, lattice::FindAxisGrid(py, search_y));
  std::string period_evidence;
  StatusOr<GridPair> resolved = ResolvePeriods(work, grids_x, grids_y, &period_evidence);
  if (!resolved.ok()) {
    *tiles_may_abut = true;
    return resolved.status();
  }
  const GridPair& grids = *resolved;
  const AxisGrid& gx = grids.x;
  const AxisGrid& gy = grids.y;
  // A size not given is only believed where the tiles show one scene: a photo's content lines
  // (a horizon, a lawn's edge) can pass for gaps.
  const bool size_given = options.rows > 0 && options.cols > 0;
  double agreement = grids.agreement;
  if (!size_given && gx.count * gy.count > 1 && agreement < 0) {
    agreement = lattice::TileAgreement(work, gx.gaps, gy.gaps);
    if (agreement < lattice::kSameSceneAgreement) {
      *tiles_may_abut = true;
      return NotFoundError(Format("no lattice: the gaps fit %.0f columns x %.0f rows, but ", gx.count, gy.count) +
                           (agreement == lattice::kTilesTooThin
                                ? std::string("those tiles are too thin to be views")
                                : Format("those tiles do not show one scene (agreement of neighbouring tiles %.2f < "
                                         "%.2f): content lines taken for gaps?",
                                         agreement,
                                         lattice::kSameSceneAgreement)));
    }
  }
  if (gx.count == 1 && gy.count == 1) {
    *tiles_may_abut = true;
    const int bx = px.ArgMaxZ(0, px.size()), by = py.ArgMaxZ(0, py.size());
    return NotFoundError(Format("no lattice: no gap or tile edge crosses the frame (strongest line evidence: z %.1f "
                                "at x=%.0f, ",
                                px.z[bx],
                                ToSensor(bx, s_x)) +
                         Format("z %.1f at y=%.0f; need z >= %.0f)", py.z[by], ToSensor(by, s_y), options.min_gap_z));
  }
  double gap_level = 0, tile_level = 0;
  GapAndTileLevels(px, gx, py, gy, &gap_level, &tile_level);
  const AxisPlan plan_x = PlanAxis(px, gx, gap_level, tile_level, s_x, width);
  const AxisPlan plan_y = PlanAxis(py, gy, gap_level, tile_level, s_y, height);

  const int rows = plan_y.count, cols = plan_x.count;
  const double max_slope = std::tan((options.max_rotation_deg + kRotationToleranceDeg) * CV_PI / 180.0);
  std::vector<TileFits> fits(rows * cols);
  cv::parallel_for_(cv::Range(0, rows * cols), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      const int r = i / cols, c = i % cols;
      const double y0 = CoarseStart(plan_y, r), y1 = CoarseEnd(plan_y, r);
      const double x0 = CoarseStart(plan_x, c), x1 = CoarseEnd(plan_x, c);
      TileFits& f = fits[i];
      f.edges[lattice::kLeft] = FitPlannedEdge(frame.grey, false, plan_x, c, true, y0, y1, max_slope);
      f.edges[lattice::kRight] = FitPlannedEdge(frame.grey, false, plan_x, c, false, y0, y1, max_slope);
      f.edges[lattice::kTop] = FitPlannedEdge(frame.grey, true, plan_y, r, true, x0, x1, max_slope);
      f.edges[lattice::kBottom] = FitPlannedEdge(frame.grey, true, plan_y, r, false, x0, x1, max_slope);
    }
  });
  FillFromAcrossTheGap(&fits, rows, cols);

  LatticeDetection detection;
  LatticeReport& report = detection.report;
  report.rows = rows;
  report.cols = cols;
  double inliers = 0;
  for (int i = 0; i < rows * cols; ++i) {
    TileGeometry geometry;
    report.tiles.push_back(AssembleTile(i / cols, i % cols, fits[i], &geometry));
    inliers += report.tiles.back().inlier_fraction;
  }
  PX_RETURN_IF_ERROR(CheckTiles(report.tiles, options));
  detection.layout = LayoutFromTiles(
      report.tiles, rows, cols, frame.grey.size(), std::vector<TileOrientation>(rows * cols, options.orientation));
  const Status valid = detection.layout.Validate();
  if (!valid.ok()) return NotFoundError("no lattice: the edges found do not form one: " + valid.message());
  std::vector<double> z;
  for (const AxisGrid* g : {&gx, &gy}) z.insert(z.end(), g->gap_z.begin(), g->gap_z.end());
  report.weakest_gap_z = *std::min_element(z.begin(), z.end());
  report.tile_agreement = agreement;
  report.confidence = (inliers / (rows * cols)) * std::min(1.0, report.weakest_gap_z / (2 * options.min_gap_z));
  if (report.confidence < options.min_confidence) {
    return NotFoundError("no lattice: the " + std::to_string(cols) + "x" + std::to_string(rows) +
                         " grid that fits best is too uncertain: confidence " +
                         Format("%.2f < %.2f (weakest gap z %.1f, edges found on %.0f%% of the cuts)",
                                report.confidence,
                                options.min_confidence,
                                report.weakest_gap_z,
                                100 * inliers / (rows * cols)));
  }
  report.evidence = Evidence(frame, detection.layout, &plan_x, &plan_y, report.tiles);
  report.evidence.insert(report.evidence.begin(),
                         Format("%.0f columns x %.0f rows, weakest gap z %.1f", cols, rows, report.weakest_gap_z));
  if (!period_evidence.empty()) {
    report.evidence.insert(report.evidence.begin() + 1, period_evidence);
  } else if (agreement >= 0) {
    report.evidence.insert(report.evidence.begin() + 1, Format("neighbouring tiles agree %.2f", agreement));
  }
  return detection;
}

// The median of an 8-bit histogram.
int HistogramMedian(const std::array<int64_t, 256>& histogram, int64_t total) {
  int64_t seen = 0;
  for (int level = 0; level < 256; ++level) {
    seen += histogram[level];
    if (2 * seen >= total) return level;
  }
  return 255;
}

// Dark (-1) or bright (+1) gaps between the prior's tiles, from the pixels outside every tile
// (every other pixel of every other row); 0 when tiles touch or gaps look like tiles.
int PriorGapPolarity(const GreyFrame& frame, const LatticeLayout& prior) {
  std::array<int64_t, 256> gap{}, tile{};
  int64_t gaps = 0, tiles = 0;
  for (int y = 0; y < frame.grey.rows; y += 2) {
    const uchar* row = frame.grey.ptr<uchar>(y);
    for (int x = 0; x < frame.grey.cols; x += 2) {
      bool inside = false;
      for (const Tile& t : prior.tiles) inside = inside || t.rect.contains({x, y});
      ++(inside ? tile : gap)[row[x]];
      ++(inside ? tiles : gaps);
    }
  }
  if (gaps < 64 || tiles < 64) return 0;
  const int g = HistogramMedian(gap, gaps), t = HistogramMedian(tile, tiles);
  if (g < t - 10) return -1;
  if (g > t + 10) return 1;
  return 0;
}

LatticeLayout ScaledPrior(const LatticeLayout& prior, const cv::Size& size) {
  if (prior.sensor_width == size.width && prior.sensor_height == size.height) return prior;
  LatticeLayout scaled = prior;
  const double sx = static_cast<double>(size.width) / prior.sensor_width;
  const double sy = static_cast<double>(size.height) / prior.sensor_height;
  scaled.sensor_width = size.width;
  scaled.sensor_height = size.height;
  for (Tile& tile : scaled.tiles) {
    const cv::Rect& r = tile.rect;
    tile.rect = cv::Rect(static_cast<int>(std::lround(r.x * sx)),
                         static_cast<int>(std::lround(r.y * sy)),
                         static_cast<int>(std::lround(r.width * sx)),
                         static_cast<int>(std::lround(r.height * sy)));
  }
  return scaled;
}

// Edge `side` of a prior tile as a line (x = a + b y for left/right, y = a + b x for top/bottom),
// with the range along it.
EdgeLine PriorEdge(const Tile& tile, int side, double* along_begin, double* along_end) {
  const std::array<cv::Point2d, 4> c = TileCorners(tile);  // tl, tr, br, bl
  const cv::Point2d& p = side == lattice::kLeft    ? c[0]
                         : side == lattice::kRight ? c[1]
                         : side == lattice::kTop   ? c[0]
                                                   : c[3];
  const cv::Point2d& q = side == lattice::kLeft    ? c[3]
                         : side == lattice::kRight ? c[2]
                         : side == lattice::kTop   ? c[1]
                                                   : c[2];
  if (side <= lattice::kRight) {
    const double b = (q.x - p.x) / (q.y - p.y);
    *along_begin = p.y;
    *along_end = q.y;
    return {p.x - b * p.y, b};
  }
  const double b = (q.y - p.y) / (q.x - p.x);
  *along_begin = p.x;
  *along_end = q.x;
  return {p.y - b * p.x, b};
}

StatusOr<LatticeDetection> DetectNearPrior(const GreyFrame& frame,
                                           const LatticeOptions& options,
                                           const LatticeLayout& given) {
  PX_RETURN_IF_ERROR(given.Validate().WithContext("prior lattice"));
  if ((options.rows != 0 && options.rows != given.rows) || (options.cols != 0 && options.cols != given.cols)) {
    return InvalidArgumentError("lattice detection: options ask for " + std::to_string(options.rows) + "x" +
                                std::to_string(options.cols) + " tiles but the prior has " +
                                std::to_string(given.rows) + "x" + std::to_string(given.cols));
  }
  const cv::Size size = frame.grey.size();
  const double aspect_change =
      (static_cast<double>(size.width) / given.sensor_width) / (static_cast<double>(size.height) / given.sensor_height);
  if (std::abs(aspect_change - 1) > 0.02) {
    return InvalidArgumentError("lattice detection: the prior lattice is for a " + std::to_string(given.sensor_width) +
                                "x" + std::to_string(given.sensor_height) + " sensor, the frame is " +
                                std::to_string(size.width) + "x" + std::to_string(size.height) +
                                " (another aspect ratio)");
  }
  const LatticeLayout prior = ScaledPrior(given, size);
  const int polarity = PriorGapPolarity(frame, prior);
  const double max_slope = std::tan((options.max_rotation_deg + kRotationToleranceDeg) * CV_PI / 180.0);
  LatticeDetection detection;
  LatticeReport& report = detection.report;
  report.rows = prior.rows;
  report.cols = prior.cols;
  report.used_prior = true;
  int tiles_found = 0, edges_searched = 0, edges_found = 0;
  double inliers = 0;
  for (const Tile& prior_tile : prior.tiles) {
    TileFits fits;
    for (int side = 0; side < 4; ++side) {
      EdgeResult& e = fits.edges[side];
      double along_begin = 0, along_end = 0;
      const EdgeLine expected = PriorEdge(prior_tile, side, &along_begin, &along_end);
      const bool vertical = side <= lattice::kRight;
      const double border =
          side == lattice::kLeft || side == lattice::kTop ? -0.5 : (vertical ? size.width : size.height) - 0.5;
      e.line = expected;
      if (std::abs(expected.a + expected.b * 0.5 * (along_begin + along_end) - border) < 1.0) {
        e.fixed = true;  // the tile runs to the frame's border
        continue;
      }
      const double length = along_end - along_begin;
      EdgeSearch search;
      search.expected = expected;
      search.along_begin = along_begin + kCornerMargin * length;
      search.along_end = along_end - kCornerMargin * length;
      search.behind_px = search.ahead_px = options.prior_search_px + std::tan(CV_PI / 180.0) * 0.5 * length;
      search.max_slope = max_slope;
      const bool start = side == lattice::kLeft || side == lattice::kTop;
      search.sign = start ? -polarity : polarity;
      search.gap_side = polarity < 0 ? (start ? -1 : 1) : 0;  // as in FitPlannedEdge
      search.transposed = !vertical;
      e.fit = lattice::FitEdge(frame.grey, search);
      if (e.fit.found) e.line = e.fit.line;
    }
    for (const EdgeResult& e : fits.edges) {
      edges_searched += e.fixed ? 0 : 1;
      edges_found += !e.fixed && e.fit.found ? 1 : 0;
    }
    TileGeometry geometry;
    DetectedTile tile = AssembleTile(prior_tile.row, prior_tile.col, fits, &geometry);
    inliers += tile.inlier_fraction;
    if (tile.edges_fitted >= 2) {
      ++tiles_found;
      tile.shift_px = geometry.centre - TileCentre(prior_tile);
    } else {
      tile.rect = prior_tile.rect;  // too little found: keep the prior's tile
      tile.rotation_deg = prior_tile.rotation_deg;
    }
    report.max_prior_shift_px = std::max(report.max_prior_shift_px, std::hypot(tile.shift_px.x, tile.shift_px.y));
    report.tiles.push_back(tile);
  }
  if (2 * tiles_found <= prior.NumViews()) {
    return NotFoundError("the frame does not show the prior's lattice: edges found for only " +
                         std::to_string(tiles_found) + " of " + std::to_string(prior.NumViews()) + " tiles within " +
                         Format("%.0f px", options.prior_search_px) + " of where it puts them");
  }
  // Content near a wrong prior's edges yields some edges; a lattice that is there yields nearly all.
  if (edges_found < kMinPriorEdgesFound * edges_searched) {
    return NotFoundError("the frame does not show the prior's lattice: only " + std::to_string(edges_found) +
                         " of the " + std::to_string(edges_searched) +
                         " tile edges it puts inside the frame were found within " +
                         Format("%.0f px (want %.0f%%)", options.prior_search_px, 100 * kMinPriorEdgesFound));
  }
  PX_RETURN_IF_ERROR(CheckTiles(report.tiles, options));
  std::vector<TileOrientation> orientations;
  for (const Tile& tile : prior.tiles) orientations.push_back(tile.orientation);
  detection.layout = LayoutFromTiles(report.tiles, prior.rows, prior.cols, size, orientations);
  const Status valid = detection.layout.Validate();
  if (!valid.ok())
    return NotFoundError("no lattice: the edges found near the prior do not form one: " + valid.message());
  report.confidence = inliers / prior.NumViews();
  if (report.confidence < options.min_confidence) {
    return NotFoundError("the frame does not show the prior's lattice clearly: its tile edges were found on " +
                         Format("%.0f%% of the cuts (confidence %.2f < %.2f)",
                                100 * report.confidence,
                                report.confidence,
                                options.min_confidence));
  }
  report.evidence = Evidence(frame, detection.layout, nullptr, nullptr, report.tiles);
  report.evidence.insert(
      report.evidence.begin(),
      Format("prior %.0fx%.0f: tiles moved up to %.2f px", prior.cols, prior.rows, report.max_prior_shift_px));
  return detection;
}

}  // namespace

std::string LatticeReport::Summary() const {
  std::ostringstream out;
  out << cols << "x" << rows << " tiles, confidence " << Format("%.2f", confidence);
  if (used_prior) out << Format(", prior shift up to %.1f px", max_prior_shift_px);
  for (size_t i = 0; i < evidence.size() && i < 3; ++i) out << "; " << evidence[i];
  out << Format("; %.0f ms", ms);
  return out.str();
}

// The frame (`grey`) cut into rows x cols equal tiles: a lattice of the size the user gave whose
// tiles abut (a wiggle lens's sub-images, vignetted towards each other), so that no gap stands out
// to find. Each tile is then cut down to the part its lens lit (vignette_trim.h).
LatticeDetection EvenSplit(
    const cv::Mat& grey, int rows, int cols, TileOrientation orientation, const std::string& evidence) {
  LatticeDetection detection;
  LatticeReport& report = detection.report;
  report.rows = rows;
  report.cols = cols;
  std::vector<cv::Rect> cut;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const int x0 = c * grey.cols / cols, x1 = (c + 1) * grey.cols / cols;
      const int y0 = r * grey.rows / rows, y1 = (r + 1) * grey.rows / rows;
      cut.emplace_back(x0, y0, x1 - x0, y1 - y0);
    }
  }
  const std::vector<cv::Rect> lit = lattice::LitTiles(grey, cut);
  for (int i = 0; i < rows * cols; ++i) {
    DetectedTile tile;
    tile.row = i / cols;
    tile.col = i % cols;
    tile.rect = lit[i];
    report.tiles.push_back(tile);
  }
  detection.layout =
      LayoutFromTiles(report.tiles, rows, cols, grey.size(), std::vector<TileOrientation>(rows * cols, orientation));
  report.evidence = {evidence};
  if (lit.front().size() != cut.front().size()) {
    report.evidence.push_back(Format("vignetted borders trimmed: tiles of %.0fx%.0f where the cut gave %.0fx%.0f",
                                     lit.front().width,
                                     lit.front().height,
                                     cut.front().width,
                                     cut.front().height));
  }
  return detection;
}

// The frame, its size not given, cut into the most equal tiles whose pictures show one scene
// (lattice::FindEqualCut), refining `found` (1x1 for none): a wiggle lens's sub-images, which
// abut with no gap to find, or vignette into each other only along one axis. `why` says why the
// gaps gave no lattice (empty when they gave `found`). NOT_FOUND, with `why`, when no such cut's
// tiles show one scene. The cut is even over the whole frame: where `found` had gaps along one
// axis, their bands fall at the tiles' borders (EvenSplit's trim takes off those that are dark).
StatusOr<LatticeDetection> DetectAbutting(const GreyFrame& frame,
                                          const LatticeOptions& options,
                                          cv::Size found,
                                          const std::string& why) {
  const lattice::EqualCut cut = lattice::FindEqualCut(
      WorkingFrame(frame, options), found, options.max_tiles_per_axis, options.rows, options.cols);
  if (cut.rows == 0) {
    return NotFoundError(why + (cut.tried == 0 ? std::string("; nor can it be cut into equal tiles shaped like views")
                                               : Format("; nor do equal tiles of it show one scene (in every cut "
                                                        "some neighbouring tiles agree less than %.2f)",
                                                        lattice::kSameSceneAgreement)));
  }
  LatticeDetection detection = EvenSplit(
      frame.grey,
      cut.rows,
      cut.cols,
      options.orientation,
      Format("%.0f columns x %.0f rows cut evenly: the most equal tiles whose pictures show one scene "
             "(agreement of neighbouring tiles %.2f)",
             cut.cols,
             cut.rows,
             cut.agreement) +
          (found.area() > 1 ? Format(", refining the %.0f x %.0f whose tiles, more than twice as long as wide, the "
                                     "gaps gave",
                                     found.width,
                                     found.height)
                            : ", where the gaps gave no lattice (" + why + ")"));
  detection.report.tile_agreement = cut.agreement;
  return detection;
}

StatusOr<LatticeDetection> DetectLattice(const cv::Mat& sensor_bgr,
                                         const LatticeOptions& options,
                                         const LatticeLayout* prior) {
  const auto start = std::chrono::steady_clock::now();
  PX_RETURN_IF_ERROR(options.Validate());
  PX_RETURN_IF_ERROR(CheckFrame(sensor_bgr));
  const GreyFrame frame = MakeGrey(sensor_bgr);
  if (frame.stddev < kBlankStddev) {
    return NotFoundError(
        Format("no lattice: the frame is blank (grey mean %.1f, stddev %.2f)", frame.mean, frame.stddev));
  }
  bool tiles_may_abut = false;
  StatusOr<LatticeDetection> detection =
      prior != nullptr ? DetectNearPrior(frame, options, *prior) : DetectBlind(frame, options, &tiles_may_abut);
  if (!detection.ok() && prior == nullptr && options.rows > 0 && options.cols > 0 &&
      detection.status().code() == StatusCode::kNotFound) {
    // The size is known and no gap stands out. When nothing in the frame shows another lattice
    // either (the tiles abut), cut it evenly; a frame that shows another lattice is refused.
    LatticeOptions any_size = options;
    any_size.rows = any_size.cols = 0;
    bool unused = false;
    const StatusOr<LatticeDetection> other = DetectBlind(frame, any_size, &unused);
    // An axis along which no gap stands out (a count of 1) says nothing against the size given.
    const auto contradicts = [](int found, int given) { return found > 1 && found != given; };
    if (!other.ok() ||
        (!contradicts(other->report.rows, options.rows) && !contradicts(other->report.cols, options.cols))) {
      detection = EvenSplit(frame.grey,
                            options.rows,
                            options.cols,
                            options.orientation,
                            Format("%.0f columns x %.0f rows as given, cut evenly: ", options.cols, options.rows) +
                                "no gap stands out (" + detection.status().message() + ")");
    }
  } else if (prior == nullptr && (options.rows == 0 || options.cols == 0)) {
    // The size is not known: tiles that abut along an axis leave no gap to find there. Tiles more
    // than twice as long as wide may hold several such views side by side: they are cut along
    // their length where equal parts show one scene; an axis with gaps keeps its count.
    const auto blocks_of_views = [&](const LatticeReport& found) {
      const double aspect =
          (static_cast<double>(frame.grey.cols) / found.cols) / (static_cast<double>(frame.grey.rows) / found.rows);
      return aspect > kMaxViewAspect || aspect < 1.0 / kMaxViewAspect;
    };
    if (detection.ok() && blocks_of_views(detection->report)) {
      LatticeOptions along_length = options;
      if (detection->report.rows > 1) along_length.rows = detection->report.rows;
      if (detection->report.cols > 1) along_length.cols = detection->report.cols;
      StatusOr<LatticeDetection> finer =
          DetectAbutting(frame, along_length, cv::Size(detection->report.cols, detection->report.rows), "");
      if (finer.ok()) detection = std::move(finer);
    } else if (!detection.ok() && tiles_may_abut) {
      detection = DetectAbutting(frame, options, cv::Size(1, 1), detection.status().message());
    }
  }
  if (detection.ok()) {
    detection->report.ms = MsSince(start);
  }
  return detection;
}

}  // namespace px
