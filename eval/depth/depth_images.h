// Pictures of a depth evaluation for people: the estimate and the ground truth on one colour
// scale, and where the estimate is wrong (`parallax eval depth --dump DIR`).
#pragma once

#include <filesystem>
#include <opencv2/core.hpp>
#include <string>

#include "pipeline/core/status.h"

namespace px::eval {

// Writes <dir>/<stem>_estimate.png and <stem>_truth.png (disparity or inverse depth, colour-
// mapped over the truth's range; NaN black) and <stem>_error.png: grey where |error| <= good,
// yellow up to bad, red above it, black without ground truth. CV_32F inputs of equal size.
Status WriteDepthImages(const std::filesystem::path& dir,
                        const std::string& stem,
                        const cv::Mat& estimate,
                        const cv::Mat& truth,
                        double good,
                        double bad);

// A file-name-safe version of a set or method name ("hci/antinous 3x3" -> "hci_antinous_3x3").
std::string FileStem(const std::string& name);

}  // namespace px::eval
