// The face detector on the simulator's face scenes (sim/scenes one_face, two_faces): the centre
// lens of a Pop9 at the product's size (640x480), with the faces' true boxes projected from the
// scene (each face card centres a labelled dlib box scaled to 0.17 m, so the truth is that box).
#pragma once

#include <vector>

#include "eval/faces/faces_eval.h"
#include "pipeline/core/status.h"
#include "pipeline/direct/direct_options.h"
#include "pipeline/direct/face_detector.h"

namespace px::eval {

// One FaceImageResult per scene ("sim/two_faces"). Fails naming the scene that does not load or
// whose face textures fell back to procedural ones (../shared/data absent).
StatusOr<std::vector<FaceImageResult>> RunSimFaceScenes(const direct::FaceDetector& detector,
                                                        const FaceDetectionOptions& detection,
                                                        double min_iou = 0.5);

}  // namespace px::eval
