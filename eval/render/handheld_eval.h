// The render evaluation's hand-held group: what the USB still camera's mode gives. A simulated
// scene shot by hand from four places (8 cm apart, each turned by up to 2 degrees, 640x480 at
// options.sim_scale, sensor noise, the focal length known as from EXIF) goes through the product's
// stages: structure from motion (pipeline/run CalibrateCapture), its depth range, the depth stage
// (or the exact depth, in the reconstruction's units) and the renderer. Novel viewpoints, chosen
// in the true frame, are carried into the reconstruction's by the similarity that best maps its
// poses onto the true ones (eval/calib/pose_alignment.h), so pose error counts in the figures.
#pragma once

#include <filesystem>
#include <vector>

#include "eval/render/render_eval.h"

namespace px::eval {

// One case per viewpoint and depth source.
StatusOr<std::vector<RenderEvalCase>> EvaluateSimulatedHandheld(const std::filesystem::path& scene_file,
                                                                const RenderEvalOptions& options);

}  // namespace px::eval
