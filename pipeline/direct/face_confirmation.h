// A face found on the centre view, looked for again in the other views where its depth puts it.
// Where the reconstruction has no metric scale (structure from motion) a face cannot be judged by
// its size in metres; but a real face is seen by every view, and the face-like patterns the
// cascades find in twigs, snow or foliage rarely survive a change of viewpoint.
#pragma once

#include <string>
#include <vector>

#include "pipeline/core/view.h"
#include "pipeline/direct/face_detector.h"
#include "pipeline/direct/subject.h"

namespace px::direct {

// Cascades that, agreeing on a face, make it one without looking again: the real faces of the
// real captures are found by all three (scores 60 to 120), the face-like twigs, snow and beard
// patches by one (scores 6 to 9).
inline constexpr int kCascadesForAFace = 2;

// Other views a face is looked for in (the nearest cameras first).
inline constexpr int kMaxConfirmingViews = 2;

struct FaceConfirmation {
  int views_checked = 0;     // other views where the face should lie inside the image
  int confirming_view = -1;  // ViewId value of the first view that found it again, -1: none
  std::string detail;        // for the log: where it was looked for
  // A face no checked view finds again is a face-like texture; with no view to check it, the face
  // stands.
  bool Refuted() const { return views_checked > 0 && confirming_view < 0; }
};

// Looks for `face` (a subject with known depth, on views[centre_index]) in up to
// kMaxConfirmingViews other views: its centre projected at its depth, the detector run on a window
// of four face widths around it, at the scale the centre view was searched at. Found again: a
// detection whose centre lies within one expected face width of the projection, of half to twice
// the expected size.
FaceConfirmation ConfirmFace(const Subject& face,
                             const std::vector<View>& views,
                             int centre_index,
                             const FaceDetector& detector,
                             const FaceDetectionOptions& options);

}  // namespace px::direct
