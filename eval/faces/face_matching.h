// Detections against ground-truth face boxes: a detection is a true positive when it overlaps an
// unmatched truth box with IoU >= the threshold (PASCAL VOC's rule, 0.5), matched greedily from
// the highest IoU down so each truth box and each detection counts once. A detection that matches
// no face but overlaps an `ignored` box by the threshold is neither a hit nor a false face.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace px::eval {

struct FaceMatch {
  int truth = 0;       // ground-truth faces
  int detections = 0;  // detections counted (those on ignored boxes left out)
  int true_positives = 0;
  std::vector<double> matched_iou;  // IoU of each true positive

  int FalsePositives() const { return detections - true_positives; }
  int Misses() const { return truth - true_positives; }
  // Precision and recall in [0, 1]; 1 when there is nothing to get wrong (no detections / no faces).
  double Precision() const { return detections > 0 ? static_cast<double>(true_positives) / detections : 1.0; }
  double Recall() const { return truth > 0 ? static_cast<double>(true_positives) / truth : 1.0; }
  void Add(const FaceMatch& other);
};

FaceMatch MatchFaces(const std::vector<cv::Rect2d>& truth,
                     const std::vector<cv::Rect2d>& detections,
                     double min_iou = 0.5,
                     const std::vector<cv::Rect2d>& ignored = {});

}  // namespace px::eval
