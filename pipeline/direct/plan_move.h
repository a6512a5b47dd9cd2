// Plans one move of the taxonomy as a path through valid viewpoints (paper 4.2 and 4.3):
//   1. each endpoint's framing rule (where it looks and its focal length, 4.2.3; a dolly zoom
//      whose subject no viewpoint can turn to looks straight along the capture axis instead);
//   2. the valid region for each rule (valid_viewpoints.h) and its candidate endpoints, extremal
//      in z: forwards for an endpoint framing a subject or dollying across, backwards for the
//      wide end of a dolly-in/out and the far end of the moves along the axis;
//   3. the `num_longest` longest candidate paths, the one with the most parallax first
//      (parallax_measure.h), each checked frame by frame at the verify size until one holds (an
//      end that fails there is first pulled back along the path, re-framed by its rule; the
//      frames the search probe ranks worst are checked first); where none holds and the context
//      allows more batches, the next `num_longest`, without the endpoints most of the failed
//      ones shared;
//   4. framing: subjects kept wholly inside every frame by narrowing the zoom where needed;
//   5. the image effect: the largest aperture valid at both ends (aperture_search.h) for a focus
//      pull, at the subject's end for a depth-of-field change (it opens from a pinhole; a path
//      whose ends hold no aperture leaves the effect to the next path that holds, and is kept
//      without it only when none does), or a colour-effect layer on the subject.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "pipeline/core/status.h"
#include "pipeline/direct/camera_path.h"
#include "pipeline/direct/coverage_probe.h"
#include "pipeline/direct/direct_options.h"
#include "pipeline/direct/parallax_measure.h"
#include "pipeline/direct/scene_geometry.h"
#include "pipeline/direct/taxonomy.h"
#include "pipeline/direct/valid_viewpoints.h"

namespace px::direct {

struct PlanContext {
  const SceneGeometry* scene = nullptr;
  const SceneSamples* samples = nullptr;
  std::vector<Subject> subjects;    // largest first; moves use the first one or two
  CoverageProbe* search = nullptr;  // reduced size, for the region search
  CoverageProbe* verify = nullptr;  // larger, for the chosen path's frames and apertures
  // Batches of `num_longest` candidate paths tried before the move is given up (step 3). The
  // caller tries the taxonomy's fallbacks with one batch first: a later batch's paths are
  // shorter or start elsewhere, and a fallback move's longest paths usually show the scene
  // better; more batches are the last resort before a morph or a 2D pan. >= 1.
  int path_batches = 1;
  // The first batch whose paths are tried: the earlier ones, already tried by a call with fewer
  // batches, only decide which endpoints the later ones leave out. [0, path_batches).
  int first_batch = 0;
  const DirectOptions* options = nullptr;
  // Valid regions already searched for these subjects, by what their rule frames and how they
  // were searched: the taxonomy's fallbacks share ends (a dolly-in's ends are a dolly-out's), so
  // they reuse the searches instead of probing the renderer again. Null: no sharing.
  std::map<std::string, ValidRegion>* regions = nullptr;
};

struct MovePlanReport {
  int valid_cells_start = 0;  // grid cells with a valid viewpoint, for each endpoint's rule
  int valid_cells_end = 0;
  int candidate_paths = 0;    // start x end candidate pairs
  int paths_measured = 0;     // pairs whose parallax was measured
  int paths_verified = 0;     // pairs checked frame by frame before one held
  double parallax = 0;        // of the chosen path (ParallaxScore)
  double length_m = 0;        // distance between its endpoints
  double max_hole_score = 0;  // the largest H(V) over its checked frames (verify size)
  double focal_scale = 1;     // framing's narrowing of the zoom (1 = none)
  double aperture_m = 0;      // for depth-of-field effects
};

// The path for `choice` (move, effect, subject order). FAILED_PRECONDITION naming the reason
// when the move cannot be planned here (no valid viewpoint for an endpoint, no candidate path
// whose frames all stay valid, subjects that cannot be kept in frame): the caller falls back.
StatusOr<CameraPath> PlanMove(const MoveChoice& choice, const PlanContext& context, MovePlanReport* report);

}  // namespace px::direct
