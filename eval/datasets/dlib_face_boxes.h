// dlib's image-metadata XML (imglab format: `<image file='x.jpg'><box top left width height/>`),
// as faces_dlib_pascalvoc/training.xml ships the PASCAL VOC face boxes (../shared/data, SOURCES.md
// 11). cv::FileStorage cannot read it (the values are attributes), so a minimal parser reads the
// two elements it needs; a box with ignore='1' is kept apart (neither a miss nor a false face).
#pragma once

#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "pipeline/core/status.h"

namespace px::eval {

struct LabelledFaceImage {
  std::string file;                 // relative to the XML's folder
  int width = 0, height = 0;        // as the XML states them (0 when absent)
  std::vector<cv::Rect2d> faces;    // pixels: x = left, y = top
  std::vector<cv::Rect2d> ignored;  // boxes marked ignore='1'
};

// Parses the XML text; fails naming the element and attribute that is missing or not a number.
StatusOr<std::vector<LabelledFaceImage>> ParseDlibFaceBoxes(const std::string& xml);

// Reads and parses `xml_path`; fails naming the file when it cannot be read or holds no image.
StatusOr<std::vector<LabelledFaceImage>> LoadDlibFaceBoxes(const std::filesystem::path& xml_path);

}  // namespace px::eval
