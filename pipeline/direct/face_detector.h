// Face detection with the cascades Debian ships in opencv-data (Haar and LBP; no DNN face model
// is packaged). The detector is built from the cascades' XML *text*, so the pipeline never opens
// a file: device/ (or a test) reads /usr/share/opencv4/... and hands the contents in.
//
// Detect() runs every frontal cascade on the equalised grey image (upscaled when small, since
// the cascades' 20-24 px windows miss smaller faces) and, optionally, the profile cascade on the
// image and its mirror (the profile cascade knows one side only). A face too large for the
// frame (a close-up touching its edges) does not fit the cascades' window, so the frame padded
// by half its shorter side on every side (edges replicated) is searched too, for faces of at
// least half the frame's shorter side that two cascades agree on; such a box is cut to the frame.
// Overlapping boxes from any cascade merge into one face; a face found by more cascades or more
// neighbours scores higher.
#pragma once

#include <memory>
#include <mutex>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "pipeline/core/status.h"
#include "pipeline/direct/direct_options.h"

namespace cv {
class CascadeClassifier;
}

namespace px::direct {

struct CascadeText {
  std::string name;      // for reports: "haarcascade_frontalface_default"
  std::string xml;       // the file's contents
  bool profile = false;  // a profile-face cascade (looks for faces turned one way)
};

struct FaceBox {
  cv::Rect2d box;    // pixels of the image given to Detect
  double score = 0;  // raw detections merged into it, summed over cascades
  int cascades = 0;  // how many cascades found it
};

class FaceDetector {
 public:
  // Fails naming the cascade whose XML does not parse as an OpenCV cascade, or when no frontal
  // cascade is given.
  static StatusOr<std::unique_ptr<FaceDetector>> Create(const std::vector<CascadeText>& cascades);
  ~FaceDetector();

  // Faces in a BGR (or grey) image, largest first. Thread-safe (calls are serialised).
  std::vector<FaceBox> Detect(const cv::Mat& image, const FaceDetectionOptions& options) const;

  std::string Describe() const;  // "haarcascade_frontalface_default + haarcascade_profileface"

 private:
  struct Loaded {
    std::string name;
    bool profile = false;
    std::unique_ptr<cv::CascadeClassifier> classifier;
  };
  explicit FaceDetector(std::vector<Loaded> cascades);

  std::vector<Loaded> cascades_;
  mutable std::mutex mutex_;  // cv::CascadeClassifier::detectMultiScale is not const
};

// Intersection over union of two boxes.
double BoxIou(const cv::Rect2d& a, const cv::Rect2d& b);

}  // namespace px::direct
