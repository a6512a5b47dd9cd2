#include "pipeline/direct/subjects.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "pipeline/core/order_statistics.h"
#include "pipeline/core/stage_clock.h"
#include "pipeline/direct/face_confirmation.h"
#include "pipeline/direct/scene_geometry.h"

namespace px::direct {

namespace {

std::string BoxText(const cv::Rect2d& box) {
  char text[96];
  std::snprintf(text, sizeof(text), "%.0fx%.0f at (%.0f, %.0f)", box.width, box.height, box.x, box.y);
  return text;
}

}  // namespace

StatusOr<Subject> SubjectFromBox(const View& view,
                                 const DepthMap* depth,
                                 const cv::Rect2d& box_px,
                                 const std::string& source) {
  const cv::Rect2d image(0, 0, view.camera.width, view.camera.height);
  const cv::Rect2d clipped = box_px & image;
  if (!(clipped.width >= 1 && clipped.height >= 1)) {
    return InvalidArgumentError("subject box " + BoxText(box_px) + " lies outside view " +
                                std::to_string(view.id.value) + " (" + std::to_string(view.camera.width) + "x" +
                                std::to_string(view.camera.height) + ")");
  }
  Subject subject;
  subject.source = source;
  subject.view = view.id.value;
  subject.box_px = box_px;
  subject.depth_known = false;
  subject.depth_m = kNominalSubjectDepthM;
  subject.confident_fraction = 0;

  if (depth != nullptr && depth->depth_m.type() == CV_32F && depth->depth_m.cols == view.camera.width &&
      depth->depth_m.rows == view.camera.height) {
    const cv::Rect inner(cv::Point(static_cast<int>(std::floor(clipped.x + 0.2 * clipped.width)),
                                   static_cast<int>(std::floor(clipped.y + 0.2 * clipped.height))),
                         cv::Point(static_cast<int>(std::ceil(clipped.x + 0.8 * clipped.width)),
                                   static_cast<int>(std::ceil(clipped.y + 0.8 * clipped.height))));
    const cv::Rect region = inner & cv::Rect(0, 0, view.camera.width, view.camera.height);
    const bool has_confidence = depth->confidence.size() == depth->depth_m.size() && depth->confidence.type() == CV_32F;
    std::vector<float> confident, known;
    for (int y = region.y; y < region.y + region.height; ++y) {
      const float* d = depth->depth_m.ptr<float>(y);
      const float* c = has_confidence ? depth->confidence.ptr<float>(y) : nullptr;
      for (int x = region.x; x < region.x + region.width; ++x) {
        if (!(d[x] > 0) || !std::isfinite(d[x])) continue;
        known.push_back(d[x]);
        if (c == nullptr || c[x] >= 0.5f) confident.push_back(d[x]);
      }
    }
    const double area = std::max(1, region.area());
    subject.confident_fraction = static_cast<double>(confident.size()) / area;
    if (!confident.empty() && confident.size() >= 0.25 * area) {
      subject.depth_m = Median(confident);
      subject.depth_known = true;
    } else if (!known.empty()) {
      subject.depth_m = Median(known);
      subject.depth_known = true;
    }
  }

  const CameraModel pinhole = view.camera.WithoutDistortion();
  const Rigid3 world_from_cam = view.cam_from_world.Inverse();
  // Pixel corners of the box (pixel centres at integers: the box spans x - 0.5 .. x + w - 0.5).
  const Eigen::Vector2d corners[4] = {{box_px.x - 0.5, box_px.y - 0.5},
                                      {box_px.x + box_px.width - 0.5, box_px.y - 0.5},
                                      {box_px.x + box_px.width - 0.5, box_px.y + box_px.height - 0.5},
                                      {box_px.x - 0.5, box_px.y + box_px.height - 0.5}};
  for (int i = 0; i < 4; ++i) {
    subject.corners_in_world[i] = world_from_cam * (pinhole.Unproject(corners[i]) * subject.depth_m);
  }
  return subject;
}

DetectedFaces DetectFaces(cv::Mat image,
                          ViewId view,
                          const FaceDetector& detector,
                          const FaceDetectionOptions& options) {
  const StageClock::time_point start = StageClock::now();
  DetectedFaces found;
  found.view = view;
  found.faces = detector.Detect(image, options);
  found.detector = detector.Describe();
  found.ms = MsSince(start);
  return found;
}

StatusOr<SubjectSearch> FindSubjects(const std::vector<View>& views,
                                     const std::vector<DepthMap>& depths,
                                     int centre_index,
                                     const FaceDetector* detector,
                                     const DirectOptions& options,
                                     const DetectedFaces* detected,
                                     bool metric_scale) {
  const auto start = std::chrono::steady_clock::now();
  SubjectSearch search;
  if (views.empty()) return InvalidArgumentError("subjects: no views");
  if (centre_index < 0 || centre_index >= static_cast<int>(views.size())) {
    return InvalidArgumentError("subjects: centre view index " + std::to_string(centre_index) + " of " +
                                std::to_string(views.size()) + " views");
  }
  if (!options.subject_boxes_px.empty()) {
    const View* view = &views[centre_index];
    if (options.subject_view >= 0) {
      view = nullptr;
      for (const View& v : views) {
        if (v.id.value == options.subject_view) view = &v;
      }
      if (view == nullptr) {
        return InvalidArgumentError("direct.subject_view: no view " + std::to_string(options.subject_view));
      }
    }
    search.detector = "user regions";
    for (size_t i = 0; i < options.subject_boxes_px.size(); ++i) {
      StatusOr<Subject> subject =
          SubjectFromBox(*view, FindDepth(depths, view->id), options.subject_boxes_px[i], "user");
      if (!subject.ok()) return subject.status().WithContext("direct.subject_boxes_px[" + std::to_string(i) + "]");
      search.subjects.push_back(std::move(subject).value());
    }
  } else if (!options.faces.enabled || options.faces.max_subjects == 0) {
    search.detector = "face detection off";
  } else if (detector == nullptr && (detected == nullptr || detected->view != views[centre_index].id)) {
    search.detector = "no face detector (cascades not loaded)";
  } else {
    const View& view = views[centre_index];
    const DepthMap* depth = FindDepth(depths, view.id);
    const bool found_before = detected != nullptr && detected->view == view.id;
    search.detector = found_before ? detected->detector : detector->Describe();
    const std::vector<FaceBox> faces = found_before ? detected->faces : detector->Detect(view.image, options.faces);
    search.detections = static_cast<int>(faces.size());
    for (const FaceBox& face : faces) {
      StatusOr<Subject> subject = SubjectFromBox(view, depth, face.box, "face");
      if (!subject.ok()) continue;
      subject->score = face.score;
      if (subject->depth_known && !metric_scale) {
        // No size in metres to judge it by. A face that several cascades agree on stands; one
        // cascade's find must be found again by the other views.
        std::string why = detector == nullptr ? "no detector to look for it again"
                                              : "found by " + std::to_string(face.cascades) + " cascades";
        if (detector != nullptr && face.cascades < kCascadesForAFace) {
          const FaceConfirmation confirmation = ConfirmFace(*subject, views, centre_index, *detector, options.faces);
          if (confirmation.Refuted()) {
            search.notes.push_back("face " + BoxText(face.box) +
                                   " dropped: not found again where its depth puts it in the other views (" +
                                   confirmation.detail + "; a face-like texture)");
            continue;
          }
          why = confirmation.confirming_view >= 0
                    ? "found again in view " + std::to_string(confirmation.confirming_view)
                    : confirmation.detail;
        }
        search.notes.push_back(
            "face " + BoxText(face.box) +
            " kept without a size check (the views' scale is not metric, structure from motion): " + why);
      } else if (subject->depth_known) {
        const double width_m = face.box.width * subject->depth_m / view.camera.fx;
        if (width_m < options.faces.min_face_width_m || width_m > options.faces.max_face_width_m) {
          char note[200];
          std::snprintf(note,
                        sizeof(note),
                        "face %s dropped: %.2f m wide at %.2f m, outside %.2f..%.2f m (a face-like texture)",
                        BoxText(face.box).c_str(),
                        width_m,
                        subject->depth_m,
                        options.faces.min_face_width_m,
                        options.faces.max_face_width_m);
          search.notes.push_back(note);
          continue;
        }
      }
      if (static_cast<int>(search.subjects.size()) >= options.faces.max_subjects) {
        search.notes.push_back("face " + BoxText(face.box) + " not used: the " +
                               std::to_string(options.faces.max_subjects) + " largest are kept");
        continue;
      }
      search.subjects.push_back(std::move(subject).value());
    }
  }
  for (const Subject& subject : search.subjects) {
    if (!subject.depth_known) {
      search.notes.push_back(subject.source + " " + BoxText(subject.box_px) + " has no depth; placed at a nominal " +
                             std::to_string(kNominalSubjectDepthM) + " m for 2D framing only");
    } else if (subject.confident_fraction < options.min_confident_fraction) {
      char note[200];
      std::snprintf(note,
                    sizeof(note),
                    "%s %s: only %.0f%% of its depth is confident (median %.2f m used)",
                    subject.source.c_str(),
                    BoxText(subject.box_px).c_str(),
                    100 * subject.confident_fraction,
                    subject.depth_m);
      search.notes.push_back(note);
    }
  }
  search.ms = MsSince(start);
  return search;
}

}  // namespace px::direct
