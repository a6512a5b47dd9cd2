// `parallax eval faces`: the product's face detector (pipeline/direct/face_detector.h, with the
// pipeline's FaceDetectionOptions) on real photos with hand-labelled face boxes
// (faces_dlib_pascalvoc: 4 PASCAL VOC photos, 18 faces), scored per image and overall.
#pragma once

#include <filesystem>
#include <functional>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "eval/faces/face_matching.h"
#include "pipeline/core/status.h"
#include "pipeline/direct/direct_options.h"
#include "pipeline/direct/face_detector.h"

namespace px::eval {

struct FacesEvalOptions {
  std::filesystem::path data_dir;  // ../shared/data (holds faces_dlib_pascalvoc/); empty: SharedDataDir()
  FaceDetectionOptions detection;  // default: what the pipeline uses
  double min_iou = 0.5;            // a detection is a hit at IoU >= this, (0, 1]
  std::function<void(const std::string& image, double fraction)> progress;  // may be empty

  Status Validate() const;
};

struct FaceImageResult {
  std::string file;
  cv::Size size;
  FaceMatch match;
  std::vector<cv::Rect2d> detections;  // as the detector returned them (largest first)
  double ms = 0;                       // Detect() wall time
};

struct FacesEvalResult {
  std::string detector;  // the cascades, FaceDetector::Describe()
  std::vector<FaceImageResult> images;
  FaceMatch total;
  double mean_ms = 0;
};

// The folder faces_dlib_pascalvoc/ under `data_dir`.
std::filesystem::path DlibFacesDir(const std::filesystem::path& data_dir);

// Fails naming the folder or file when the set is absent or unreadable, or the options are out of range.
StatusOr<FacesEvalResult> RunFacesEval(const direct::FaceDetector& detector, const FacesEvalOptions& options);

}  // namespace px::eval
