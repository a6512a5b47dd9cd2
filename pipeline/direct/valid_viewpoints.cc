#include "pipeline/direct/valid_viewpoints.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <opencv2/core/utility.hpp>
#include <optional>
#include <string>

namespace px::direct {

namespace {

struct Probed {
  bool valid = false;
  double hole_score = 0;
  Framing framing;
};

// One cell's column of positions along z. Probes are remembered by z, so a position asked for
// twice (a neighbour's answer tried while looking for a valid anchor, then as a search's first
// step) costs one coverage measurement.
class ColumnSearch {
 public:
  ColumnSearch(const SceneGeometry& scene,
               const FramingRule& rule,
               CoverageProbe* probe,
               double max_enlargement,
               Eigen::Vector2d xy)
      : scene_(scene), rule_(rule), probe_(probe), xy_(std::move(xy)) {
    // The approach is limited, not the move's framing: what the cell's own position at z = 0
    // enlarges (a zoom past the limit, a cell a little nearer an off-axis subject) still holds
    // there and behind it.
    const Framing at_capture = rule_(scene_.WorldFromRig(Eigen::Vector3d(xy_.x(), xy_.y(), 0.0)));
    max_enlargement_ = std::max(max_enlargement, AimEnlargement(scene_, at_capture));
  }

  StatusOr<Probed> At(double z) {
    for (const auto& [probed_z, probed] : probed_) {
      if (probed_z == z) return probed;
    }
    Probed result;
    result.framing = rule_(scene_.WorldFromRig(Eigen::Vector3d(xy_.x(), xy_.y(), z)));
    if (AimEnlargement(scene_, result.framing) > max_enlargement_) {
      // Nearer than the capture's detail allows: invalid without a probe (H(V) says nothing).
      result.hole_score = std::numeric_limits<double>::infinity();
    } else if (result.framing.focal_px > 0) {  // else the rule cannot frame from here
      PX_ASSIGN_OR_RETURN(
          result.hole_score,
          probe_->HoleScore(scene_.OutputWithFocal(result.framing.focal_px), result.framing.cam_from_world));
      result.valid = result.hole_score < probe_->valid_hole_score();
      ++probes_;
    }
    probed_.emplace_back(z, result);
    return result;
  }

  // The farthest valid z in direction `sign` (+1 forwards, -1 backwards) from the valid `anchor`
  // at `anchor_z`, not past `limit_z`, to within z.precision_m. `hint_z` (a neighbour's answer)
  // is tried first: when valid, the search steps on from it by the precision, doubling; when
  // not, it steps back from it the same way (the answer is usually a step or two away, so a
  // cell costs about two probes a direction instead of a search from the anchor; an anchor at
  // the hint steps on by the precision too). Without a hint the step starts at
  // z.first_step_m, doubling while valid; then halving between the last valid and the first
  // invalid distance. Sets last_z() to the answer's z.
  StatusOr<Probed> Extreme(const Probed& anchor,
                           double anchor_z,
                           double sign,
                           double limit_z,
                           const ZLimits& z,
                           std::optional<double> hint_z) {
    Probed best = anchor;
    const double limit = sign * (limit_z - anchor_z);  // distances from the anchor along sign
    double lo = 0;                                     // distance of `best`
    std::optional<double> hi;                          // first invalid distance found
    // With a neighbour's answer the frontier is expected near it: small steps.
    double step = hint_z ? z.precision_m : z.first_step_m;
    const auto probe_at = [&](double distance) { return At(anchor_z + sign * distance); };
    if (hint_z && sign * (*hint_z - anchor_z) > z.precision_m && limit > 0) {
      const double hint = std::min(sign * (*hint_z - anchor_z), limit);
      PX_ASSIGN_OR_RETURN(Probed at, probe_at(hint));
      if (at.valid) {
        best = at;
        lo = hint;
      } else {
        hi = hint;
        for (double back = step; *hi - back > lo; back *= 2) {
          PX_ASSIGN_OR_RETURN(Probed nearer, probe_at(*hi - back));
          if (nearer.valid) {
            best = nearer;
            lo = *hi - back;
            break;
          }
          hi = *hi - back;
        }
      }
    }
    while (!hi && lo < limit - 1e-9) {
      const double next = std::min(limit, lo + step);
      PX_ASSIGN_OR_RETURN(Probed at, probe_at(next));
      if (at.valid) {
        best = at;
        lo = next;
        step *= 2;
      } else {
        hi = next;
      }
    }
    // A bracket one precision step wide is resolved (the tolerance absorbs the rounding of z).
    while (hi && *hi - lo > z.precision_m * (1 + 1e-6)) {
      const double mid = 0.5 * (lo + *hi);
      PX_ASSIGN_OR_RETURN(Probed at, probe_at(mid));
      if (at.valid) {
        best = at;
        lo = mid;
      } else {
        hi = mid;
      }
    }
    last_z_ = anchor_z + sign * std::max(0.0, lo);
    return best;
  }

  int probes() const { return probes_; }
  double last_z() const { return last_z_; }

 private:
  const SceneGeometry& scene_;
  const FramingRule& rule_;
  CoverageProbe* probe_;
  Eigen::Vector2d xy_;
  double max_enlargement_ = 0;
  std::vector<std::pair<double, Probed>> probed_;
  int probes_ = 0;
  double last_z_ = 0;
};

}  // namespace

double AimEnlargement(const SceneGeometry& scene, const Framing& framing) {
  if (!framing.aim_in_world || !(scene.focal_px > 0)) return 1.0;
  const double from_capture = (*framing.aim_in_world - scene.WorldFromRig(Eigen::Vector3d::Zero())).norm();
  const double from_framing = (*framing.aim_in_world - framing.centre_in_world).norm();
  if (!(from_framing > 0)) return std::numeric_limits<double>::infinity();
  return framing.focal_px / scene.focal_px * from_capture / from_framing;
}

ZLimits SearchLimits(const SceneGeometry& scene, const ViewpointSearchOptions& options) {
  ZLimits z;
  // A clip smaller than the capture has detail to spare: its frames may enlarge that much more.
  z.max_enlargement = options.max_enlargement / std::min(1.0, scene.output_scale);
  z.forward_m = options.max_forward * scene.near_depth_m;
  z.back_m = options.max_back * scene.median_depth_m;
  z.first_step_m = options.z_first_step * scene.median_depth_m;
  z.precision_m = options.z_precision * scene.median_depth_m;
  return z;
}

StatusOr<std::vector<Eigen::Vector2d>> GridPositions(const SceneGeometry& scene,
                                                     const ViewpointSearchOptions& options) {
  Eigen::Vector2d extent = scene.box_max - scene.box_min;
  const double longer = extent.maxCoeff();
  if (!(longer >= 1e-3)) {
    return FailedPreconditionError("direction: the viewpoints span " + std::to_string(longer * 1000) +
                                   " mm, want at least 1 mm to search a path across");
  }
  for (int axis = 0; axis < 2; ++axis) extent[axis] = std::max(extent[axis], 0.5 * longer);
  const Eigen::Vector2d centre = 0.5 * (scene.box_min + scene.box_max);
  const Eigen::Vector2d half = 0.5 * options.grid_extent * extent;
  const int n = options.grid_size;
  std::vector<Eigen::Vector2d> positions;
  for (int r = 0; r < n; ++r) {
    for (int c = 0; c < n; ++c) {
      const double fx = n > 1 ? static_cast<double>(c) / (n - 1) : 0.5;
      const double fy = n > 1 ? static_cast<double>(r) / (n - 1) : 0.5;
      positions.emplace_back(centre.x() - half.x() + 2 * half.x() * fx, centre.y() - half.y() + 2 * half.y() * fy);
    }
  }
  return positions;
}

namespace {

// A cell's expected answer (z) from its neighbours' in the chain: the last valid cell's; with
// its left neighbour, the one above it and the one above that in the same row all answered, the
// median of the left's, the upper's and the plane through the three (left + up - up-left), since
// the frontier is smooth and a slope seen in the row above usually carries on (about a tenth
// fewer probes on the 640x480 shots than the last valid cell's answer alone).
std::optional<double> ExpectedAnswer(
    const std::map<int, double>& answers, std::optional<double> last_valid, int cell, int previous_cell, int n) {
  const int row = cell / n, column = cell % n, previous_column = previous_cell % n;
  if (row == 0 || previous_cell / n != row) return last_valid;
  const auto left = answers.find(previous_cell), up = answers.find(cell - n),
             up_left = answers.find((row - 1) * n + previous_column);
  if (left == answers.end() || up == answers.end() || up_left == answers.end() ||
      std::abs(column - previous_column) != 1) {
    return last_valid;
  }
  std::array<double, 3> guesses = {left->second, up->second, left->second + up->second - up_left->second};
  std::sort(guesses.begin(), guesses.end());
  return guesses[1];
}

// The search along one chain of cells, each seeded by the previous cells' answers.
StatusOr<ValidRegion> SearchChain(const SceneGeometry& scene,
                                  const FramingRule& rule,
                                  CoverageProbe* probe,
                                  const ZLimits& z,
                                  const std::vector<Eigen::Vector2d>& positions,
                                  const std::vector<int>& order,
                                  bool search_front,
                                  bool search_back) {
  ValidRegion region;
  const int n = std::max(1, static_cast<int>(std::lround(std::sqrt(static_cast<double>(positions.size())))));
  std::optional<double> last_front, last_back;        // the last valid cell's answers (z)
  std::map<int, double> front_answers, back_answers;  // by cell, this chain's
  int previous_cell = -1;
  for (int cell : order) {
    ++region.cells;
    const std::optional<double> front_hint = ExpectedAnswer(front_answers, last_front, cell, previous_cell, n);
    const std::optional<double> back_hint = ExpectedAnswer(back_answers, last_back, cell, previous_cell, n);
    previous_cell = cell;
    ColumnSearch column(scene, rule, probe, z.max_enlargement, positions[cell]);
    // A valid position to search from. The neighbour's answers first: next to a valid cell they
    // usually hold, and then the searches start there (no probe at z = 0 is needed).
    std::optional<Probed> anchor;
    double anchor_z = 0;
    for (const auto& [wanted, hint] : {std::pair{search_front, front_hint}, std::pair{search_back, back_hint}}) {
      if (anchor || !wanted || !hint) continue;
      PX_ASSIGN_OR_RETURN(Probed at, column.At(*hint));
      if (at.valid) {
        anchor = at;
        anchor_z = *hint;
      }
    }
    if (!anchor) {
      PX_ASSIGN_OR_RETURN(Probed origin, column.At(0.0));
      if (origin.valid) anchor = origin;
    }
    // A view turned towards a subject off the axis lacks rays at its far edge from z = 0, but
    // nearer the scene the same edge falls on surfaces the inputs saw: step forwards, doubling.
    for (double ahead_m = z.first_step_m; !anchor && search_front && ahead_m <= z.forward_m; ahead_m *= 2) {
      PX_ASSIGN_OR_RETURN(Probed ahead, column.At(ahead_m));
      if (ahead.valid) {
        anchor = ahead;
        anchor_z = ahead_m;
      }
    }
    if (!anchor) {
      region.probes += column.probes();
      continue;
    }
    ++region.valid_cells;
    if (search_front) {
      PX_ASSIGN_OR_RETURN(Probed front, column.Extreme(*anchor, anchor_z, +1.0, z.forward_m, z, front_hint));
      last_front = front_answers[cell] = column.last_z();
      region.front.push_back({front.framing, front.hole_score, cell});
    }
    if (search_back) {
      PX_ASSIGN_OR_RETURN(Probed back, column.Extreme(*anchor, anchor_z, -1.0, -z.back_m, z, back_hint));
      last_back = back_answers[cell] = column.last_z();
      region.back.push_back({back.framing, back.hole_score, cell});
    }
    region.probes += column.probes();
  }
  return region;
}

// Serpentine over rows [first, last): each cell follows a neighbour, whose answer seeds it.
std::vector<int> Serpentine(int n, int first, int last) {
  std::vector<int> order;
  for (int r = first; r < last; ++r) {
    for (int k = 0; k < n; ++k) order.push_back(r * n + (r % 2 == 0 ? k : n - 1 - k));
  }
  return order;
}

}  // namespace

StatusOr<ValidRegion> FindValidViewpoints(const SceneGeometry& scene,
                                          const FramingRule& rule,
                                          CoverageProbe* probe,
                                          const ViewpointSearchOptions& options,
                                          Sweep sweep,
                                          bool search_front,
                                          bool search_back) {
  const ZLimits z = SearchLimits(scene, options);
  std::vector<Eigen::Vector2d> positions;
  std::vector<std::vector<int>> chains;
  if (sweep == Sweep::kAxis) {
    positions.push_back(0.5 * (scene.box_min + scene.box_max));
    chains.push_back({0});
  } else {
    PX_ASSIGN_OR_RETURN(positions, GridPositions(scene, options));
    const int n = options.grid_size;
    // A probe that may run concurrently searches the grid's two halves side by side (2 cores);
    // the halves' chains are fixed, so the answer does not depend on the threads' timing.
    if (probe->concurrent() && n >= 4) {
      chains = {Serpentine(n, 0, n / 2), Serpentine(n, n / 2, n)};
    } else {
      chains = {Serpentine(n, 0, n)};
    }
  }
  std::vector<StatusOr<ValidRegion>> found(chains.size(), InternalError("chain not searched"));
  const auto search = [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      found[i] = SearchChain(scene, rule, probe, z, positions, chains[i], search_front, search_back);
    }
  };
  if (chains.size() > 1) {
    cv::parallel_for_(cv::Range(0, static_cast<int>(chains.size())), search, static_cast<double>(chains.size()));
  } else {
    search(cv::Range(0, 1));
  }
  ValidRegion region;
  for (StatusOr<ValidRegion>& part : found) {
    if (!part.ok()) return part.status();
    region.cells += part->cells;
    region.valid_cells += part->valid_cells;
    region.probes += part->probes;
    region.front.insert(region.front.end(), part->front.begin(), part->front.end());
    region.back.insert(region.back.end(), part->back.begin(), part->back.end());
  }
  return region;
}

}  // namespace px::direct
