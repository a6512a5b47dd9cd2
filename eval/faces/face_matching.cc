#include "eval/faces/face_matching.h"

#include <algorithm>
#include <tuple>

#include "pipeline/direct/face_detector.h"

namespace px::eval {

void FaceMatch::Add(const FaceMatch& other) {
  truth += other.truth;
  detections += other.detections;
  true_positives += other.true_positives;
  matched_iou.insert(matched_iou.end(), other.matched_iou.begin(), other.matched_iou.end());
}

FaceMatch MatchFaces(const std::vector<cv::Rect2d>& truth,
                     const std::vector<cv::Rect2d>& detections,
                     double min_iou,
                     const std::vector<cv::Rect2d>& ignored) {
  std::vector<std::tuple<double, size_t, size_t>> pairs;  // (IoU, truth, detection)
  for (size_t t = 0; t < truth.size(); ++t) {
    for (size_t d = 0; d < detections.size(); ++d) {
      const double iou = direct::BoxIou(truth[t], detections[d]);
      if (iou >= min_iou) pairs.emplace_back(iou, t, d);
    }
  }
  std::sort(pairs.begin(), pairs.end(), [](const auto& a, const auto& b) { return std::get<0>(a) > std::get<0>(b); });
  std::vector<bool> truth_used(truth.size(), false), detection_used(detections.size(), false);
  FaceMatch match;
  match.truth = static_cast<int>(truth.size());
  for (const auto& [iou, t, d] : pairs) {
    if (truth_used[t] || detection_used[d]) continue;
    truth_used[t] = detection_used[d] = true;
    match.true_positives += 1;
    match.matched_iou.push_back(iou);
  }
  for (size_t d = 0; d < detections.size(); ++d) {
    const bool on_ignored =
        !detection_used[d] && std::any_of(ignored.begin(), ignored.end(), [&](const cv::Rect2d& box) {
          return direct::BoxIou(box, detections[d]) >= min_iou;
        });
    if (!on_ignored) match.detections += 1;
  }
  return match;
}

}  // namespace px::eval
