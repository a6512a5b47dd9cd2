// Subjects of interest (paper 4.1, 4.2.3): faces detected on the centre view, or regions the
// user marked, each turned into a 3D quadrilateral at the median depth inside its box.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "pipeline/core/status.h"
#include "pipeline/core/view.h"
#include "pipeline/direct/direct_options.h"
#include "pipeline/direct/face_detector.h"
#include "pipeline/direct/subject.h"

namespace px::direct {

// The depth a subject box is placed at when its view has no usable depth: only 2D framing
// (a pan and zoom, a morph) uses such a subject, and for those any depth on the ray is the same.
inline constexpr double kNominalSubjectDepthM = 1.0;

// The subject for `box_px` in `view`: the median depth of the box's inner 60 % (a face box's
// rim holds background) over pixels with confident depth (confidence >= 0.5) when at least a
// quarter of them are, else over all known depth; the quadrilateral is the box's corners at that
// depth, fronto-parallel to the view. `depth` may be null (then depth_known is false and the
// nominal depth is used). Fails naming the box when it does not overlap the image.
StatusOr<Subject> SubjectFromBox(const View& view,
                                 const DepthMap* depth,
                                 const cv::Rect2d& box_px,
                                 const std::string& source);

// Faces already found on a view (pipeline/run detects them on the centre view while the depth
// stage runs: detection needs the image only).
struct DetectedFaces {
  ViewId view;
  std::vector<FaceBox> faces;
  std::string detector;  // FaceDetector::Describe()
  double ms = 0;         // wall time of the detection
};

// Runs `detector` on one view's image and times it. The image is taken by value (shared, not
// copied) so that the pipeline can detect on another thread while the views change.
DetectedFaces DetectFaces(cv::Mat image,
                          ViewId view,
                          const FaceDetector& detector,
                          const FaceDetectionOptions& options);

struct SubjectSearch {
  std::vector<Subject> subjects;   // largest first, at most options.faces.max_subjects
  std::vector<std::string> notes;  // rejected detections and why, low-confidence depth
  int detections = 0;              // faces the detector returned before any filtering
  std::string detector;            // the cascades used, or why none ran
  double ms = 0;                   // wall time
};

// User boxes (options.subject_boxes_px, in options.subject_view or the centre view) when given;
// else faces on views[centre_index] from `detector` (null: none, said in `detector`). A face
// whose physical width at its depth is outside options.faces' range is dropped, so that a
// face-like texture on a far wall or a tiny pattern up close does not become a subject. Without
// `metric_scale` (structure from motion's scale is a guess, and a real face would be dropped as
// 6 cm wide) a face found by a single cascade is instead looked for again in the other views
// (face_confirmation.h; with `detector` only) and dropped when none finds it; without depth, every
// face is kept, with a note. `detected`, when it is for the centre view, replaces
// the detection (its time is then not in SubjectSearch::ms).
StatusOr<SubjectSearch> FindSubjects(const std::vector<View>& views,
                                     const std::vector<DepthMap>& depths,
                                     int centre_index,
                                     const FaceDetector* detector,
                                     const DirectOptions& options,
                                     const DetectedFaces* detected = nullptr,
                                     bool metric_scale = true);

}  // namespace px::direct
