// The render evaluation's hand-held group: what the USB still camera's mode gives. A simulated
// scene shot by hand from four places (8 cm apart, each turned by up to 2 degrees, 640x480 at
// options.sim_scale, sensor noise) plus three held-out photos goes through the product's stages:
// structure from motion on all seven (pipeline/run CalibrateCapture), its depth range, the depth
// stage on the four (or the exact depth, in the reconstruction's units) and the renderer, which
// draws each held-out viewpoint at the pose SfM gave its photo, scored against a clean truth
// (LLFF's protocol: a camera placed by aligning poses onto the truth instead is a pixel out of
// register). Twice: with the focal length as EXIF gives it ("sim X hand-held") and without, so
// self-calibrated ("sim X hand-held no EXIF").
#pragma once

#include <filesystem>
#include <vector>

#include "eval/render/render_eval.h"

namespace px::eval {

// One case per viewpoint and depth source.
StatusOr<std::vector<RenderEvalCase>> EvaluateSimulatedHandheld(const std::filesystem::path& scene_file,
                                                                const RenderEvalOptions& options);

// The same shots of a scene whose plane named "face" turns (9 degrees either way) and moves
// (1.5 cm) between them, as a sitter does over the seconds a hand-held set takes; each held-out
// viewpoint's truth has the face as the shot nearest to it saw it. With the focal length as EXIF
// gives it; double images measured. NOT_FOUND when the scene has no face plane.
StatusOr<std::vector<RenderEvalCase>> EvaluateSimulatedHandheldMotion(const std::filesystem::path& scene_file,
                                                                      const RenderEvalOptions& options);

}  // namespace px::eval
