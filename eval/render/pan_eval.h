// The render evaluation's pan group: temporal steadiness. A camera on the lattice plane sees every
// pixel's ray meet the view mesh at its own centre, so the whole frame hands over from view to
// view as the camera crosses a triangle's edge: the hardest case for a clip to stay steady (a
// view's weight that jumps, an edge that flickers). A short lateral pan across such an edge is
// rendered frame by frame and scored against the ray caster's frames: the per-frame figures
// (means over the frames) and TemporalPsnr (image_metrics.h), which counts only the errors that
// come and go between frames.
#pragma once

#include <filesystem>
#include <vector>

#include "eval/render/render_eval.h"

namespace px::eval {

// Frames in the pan, and its path in lattice baselines b (rig frame, lenses b apart): on the
// lattice plane at y = 0.3 b, x from 0.1 b to 0.5 b, which crosses the diagonal of the square
// between four lenses (a triangle edge of the view mesh) at x = 0.3 b.
inline constexpr int kPanFrames = 16;

// One case per depth source: `scene_file` on the lattice `spec` at options.sim_scale.
StatusOr<std::vector<RenderEvalCase>> EvaluateSimulatedPan(const std::filesystem::path& scene_file,
                                                           const SimCameraSpec& spec,
                                                           const RenderEvalOptions& options);

}  // namespace px::eval
