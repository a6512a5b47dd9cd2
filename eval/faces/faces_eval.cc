#include "eval/faces/faces_eval.h"

#include <chrono>
#include <opencv2/imgcodecs.hpp>

#include "eval/datasets/dlib_face_boxes.h"
#include "sim/synthetic/data_paths.h"

namespace px::eval {

Status FacesEvalOptions::Validate() const {
  if (!(min_iou > 0 && min_iou <= 1)) {
    return InvalidArgumentError("faces_eval.min_iou " + std::to_string(min_iou) + " is outside (0, 1]");
  }
  return detection.Validate();
}

std::filesystem::path DlibFacesDir(const std::filesystem::path& data_dir) {
  return (data_dir.empty() ? sim::SharedDataDir() : data_dir) / "faces_dlib_pascalvoc";
}

StatusOr<FacesEvalResult> RunFacesEval(const direct::FaceDetector& detector, const FacesEvalOptions& options) {
  PX_RETURN_IF_ERROR(options.Validate());
  const std::filesystem::path dir = DlibFacesDir(options.data_dir);
  PX_ASSIGN_OR_RETURN(std::vector<LabelledFaceImage> labelled, LoadDlibFaceBoxes(dir / "training.xml"));
  FacesEvalResult result;
  result.detector = detector.Describe();
  double total_ms = 0;
  for (size_t i = 0; i < labelled.size(); ++i) {
    const LabelledFaceImage& entry = labelled[i];
    if (options.progress) options.progress(entry.file, static_cast<double>(i) / labelled.size());
    const std::filesystem::path file = dir / entry.file;
    const cv::Mat image = cv::imread(file.string(), cv::IMREAD_COLOR);
    if (image.empty()) return DataLossError("face image " + file.string() + ": cannot be read as an image");
    if (entry.width > 0 && (image.cols != entry.width || image.rows != entry.height)) {
      return DataLossError("face image " + file.string() + " is " + std::to_string(image.cols) + "x" +
                           std::to_string(image.rows) + " but training.xml says " + std::to_string(entry.width) + "x" +
                           std::to_string(entry.height));
    }
    FaceImageResult image_result;
    image_result.file = entry.file;
    image_result.size = image.size();
    const auto start = std::chrono::steady_clock::now();
    const std::vector<direct::FaceBox> faces = detector.Detect(image, options.detection);
    image_result.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    for (const direct::FaceBox& face : faces) image_result.detections.push_back(face.box);
    image_result.match = MatchFaces(entry.faces, image_result.detections, options.min_iou, entry.ignored);
    result.total.Add(image_result.match);
    total_ms += image_result.ms;
    result.images.push_back(std::move(image_result));
  }
  if (options.progress) options.progress("done", 1.0);
  result.mean_ms = result.images.empty() ? 0 : total_ms / result.images.size();
  return result;
}

}  // namespace px::eval
