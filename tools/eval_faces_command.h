// `parallax eval faces`: the product's face detector against the hand-labelled faces of
// faces_dlib_pascalvoc (eval/faces/faces_eval.h): per image and overall ground-truth faces,
// detections, true positives at IoU >= 0.5, precision, recall and time, then the simulated face
// scenes (eval/faces/sim_face_scenes.h), as a table or JSON.
#pragma once

#include <CLI/CLI.hpp>

namespace px::cli {

void AddEvalFacesCommand(CLI::App& eval);

}  // namespace px::cli
