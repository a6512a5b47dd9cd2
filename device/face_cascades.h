// Loads the face detector from the cascades Debian's opencv-data installs (the pipeline opens
// no files, so device/ reads them and hands their text in).
#pragma once

#include <filesystem>
#include <memory>

#include "pipeline/core/status.h"
#include "pipeline/direct/face_detector.h"

namespace px::device {

inline const std::filesystem::path kDefaultCascadeDir = "/usr/share/opencv4/haarcascades";

// The frontal (default, alt2) and profile Haar cascades from `dir`. NOT_FOUND naming the file
// when one is missing (install opencv-data).
StatusOr<std::shared_ptr<const direct::FaceDetector>> LoadFaceDetector(
    const std::filesystem::path& dir = kDefaultCascadeDir);

}  // namespace px::device
