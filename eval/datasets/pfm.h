// Portable Float Map (PFM) files: "Pf" (one channel) or "PF" (three), width height, scale
// (negative = little endian), then float rows stored bottom to top. Used for ground-truth
// disparities (HCI, ETH3D, Middlebury 2014).
#pragma once

#include <filesystem>
#include <opencv2/core.hpp>

#include "pipeline/core/status.h"

namespace px::eval {

// The image top row first: CV_32F (Pf) or CV_32FC3 (PF, RGB order as stored). Non-finite values
// (ETH3D's "unknown") are kept. Errors name the file and what is wrong with it.
StatusOr<cv::Mat> ReadPfm(const std::filesystem::path& path);

// Writes a CV_32F or CV_32FC3 image as little-endian PFM (for debugging and tests).
Status WritePfm(const std::filesystem::path& path, const cv::Mat& image);

}  // namespace px::eval
