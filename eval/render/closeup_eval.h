// The render evaluation's close-up group: novel views as the product's moves make them, where the
// views are magnified and cracks and jagged silhouettes show (issue 5). On the simulated Pop9 at
// 640x480, the dolly in that `parallax clip` plans for the scene (seed 1, its default) is rendered
// halfway and at its close-up end, with the depth stage and with exact depth, and scored against
// the ray caster's image of the same camera: PSNR, SSIM, the depth-edge split and the crack
// fraction (crack_measure.h). The moves are fixed here (closeup_eval.cc says where they came from),
// so later changes to the direction stage do not move these figures.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "eval/render/render_eval.h"
#include "pipeline/direct/camera_path.h"

namespace px::eval {

// Scenes with a recorded dolly in ("one_face", "two_faces"), by file stem.
std::vector<std::string> CloseUpScenes();

// The recorded dolly in of `scene` (a stem of CloseUpScenes()) for views like `source_camera` (the
// Pop9's 640x480 tile scaled by `scale`), as a linear CameraPath of 150 frames.
StatusOr<CameraPath> RecordedDollyIn(const std::string& scene, const CameraModel& source_camera, double scale);

// The close-up cases of `scene_file` (one of CloseUpScenes(), error otherwise) on the Pop9 lattice
// at options.sim_scale: 2 viewpoints per depth source.
StatusOr<std::vector<RenderEvalCase>> EvaluateSimulatedCloseUps(const std::filesystem::path& scene_file,
                                                                const RenderEvalOptions& options);

}  // namespace px::eval
