// Valid-viewpoint sampling (paper 4.2.1): a viewpoint is valid when its rendering lacks few
// enough input rays, H(V) < 2. Positions are sampled on a 12 x 12 grid across twice the
// viewpoints' bounding box at z = 0 of the capture frame, and from each, searched forwards and
// backwards along z with an adaptive step (doubled after a valid probe, halved after an invalid
// one) to the farthest valid position: the front and back surfaces of the valid region, whose
// points are the candidate path endpoints (4.2.2).
//
// A move fixes where each endpoint looks and its focal length from its position (4.2, second
// assumption), so the search takes that rule as a function. Speed: cells are visited in a
// serpentine order; each cell's searches start from its neighbour's answers (about two probes a
// direction: one valid at or near the answer, one invalid a precision step beyond), and no probe
// at z = 0 is needed when a neighbour's answer is valid there. With a probe that may run
// concurrently (the CPU renderer's Coverage, or the splat, splat_coverage.h) the grid's two halves
// are two such chains, searched side by side.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <limits>
#include <optional>
#include <vector>

#include "pipeline/core/rigid3.h"
#include "pipeline/core/status.h"
#include "pipeline/direct/coverage_probe.h"
#include "pipeline/direct/direct_options.h"
#include "pipeline/direct/scene_geometry.h"

namespace px::direct {

// One viewpoint as a move frames it.
struct Framing {
  Eigen::Vector3d centre_in_world = Eigen::Vector3d::Zero();
  Rigid3 cam_from_world;
  double focal_px = 0;
  // The point the frame is composed on (a subject, the scene centroid), when it aims at one.
  std::optional<Eigen::Vector3d> aim_in_world;
};
// How a move frames an endpoint at a given camera centre (where it looks, its focal length).
using FramingRule = std::function<Framing(const Eigen::Vector3d& centre_in_world)>;

struct Candidate {
  Framing framing;
  double hole_score = 0;  // H(V) estimated at output size
  int cell = -1;          // grid cell index (row-major), 0 for the axis sweep
};

enum class Sweep {
  kGrid,  // the paper's grid of x, y positions at z = 0
  kAxis,  // only the capture axis through the box centre (dolly-out, dolly zoom: "along z")
};

struct ValidRegion {
  std::vector<Candidate> front;  // per valid cell, its farthest valid position forwards (+z)
  std::vector<Candidate> back;   // per valid cell, its farthest valid position backwards (-z)
  int cells = 0;                 // cells sampled
  int valid_cells = 0;           // cells with any valid position
  int probes = 0;                // coverage measurements made
};

// How much `framing` enlarges the capture's detail where it aims: its focal against f, times how
// much nearer its aim point it stands than the capture's centre does. 1 where it does not aim.
double AimEnlargement(const SceneGeometry& scene, const Framing& framing);

// The z range searched, in metres of the capture frame, and the search steps.
struct ZLimits {
  double forward_m = 0;     // farthest forward position tried
  double back_m = 0;        // farthest backward position tried (positive number)
  double first_step_m = 0;  // first step without a neighbour's answer
  double precision_m = 0;   // stop halving below this
  // Largest AimEnlargement of a valid position: options.max_enlargement, more for a clip smaller
  // than the capture.
  double max_enlargement = std::numeric_limits<double>::infinity();
};
ZLimits SearchLimits(const SceneGeometry& scene, const ViewpointSearchOptions& options);

// The grid positions at z = 0 (capture frame x, y), row-major; a bounding box flat in one
// direction (a single row of lenses) is widened to half its other side so the grid has rows.
// Fails when the viewpoints span less than a millimetre.
StatusOr<std::vector<Eigen::Vector2d>> GridPositions(const SceneGeometry& scene, const ViewpointSearchOptions& options);

// Searches the valid region for `rule`. Only the directions asked for are searched.
StatusOr<ValidRegion> FindValidViewpoints(const SceneGeometry& scene,
                                          const FramingRule& rule,
                                          CoverageProbe* probe,
                                          const ViewpointSearchOptions& options,
                                          Sweep sweep,
                                          bool search_front,
                                          bool search_back);

}  // namespace px::direct
