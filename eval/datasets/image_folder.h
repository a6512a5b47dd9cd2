// A folder of hand-held photos (../shared/data/handheld/<set>, SOURCES.md 8): the JPEG and PNG
// files in name order, turned upright by their EXIF orientation, scaled so the longer side is
// at most `max_side_px`, with the focal length in pixels from EXIF when it is there.
#pragma once

#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "pipeline/core/status.h"

namespace px::eval {

struct FolderImage {
  std::string name;          // file name
  cv::Mat bgr;               // upright, scaled
  double focal_px = 0;       // for bgr's size; 0 = unknown
  std::string focal_source;  // which EXIF tags gave it ("" when unknown)
};

// Errors: the folder cannot be read, holds no images, or an image cannot be decoded (named).
StatusOr<std::vector<FolderImage>> LoadImageFolder(const std::filesystem::path& dir, int max_side_px = 1600);

}  // namespace px::eval
