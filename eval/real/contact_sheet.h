// Pictures for a person to look at beside the figures: images tiled into one sheet with a label
// under each (a clip's frames, a held-out view beside its renders and error maps).
#pragma once

#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "pipeline/core/status.h"

namespace px::eval {

struct LabelledImage {
  cv::Mat image;  // CV_8UC3 or CV_8U, any size
  std::string label;
};

// `cells` row by row, `columns` to a row, each scaled to `cell_width` px wide (aspect kept) on a
// dark grey sheet with its label in a strip below. Empty `cells`: an empty Mat.
cv::Mat ContactSheet(const std::vector<LabelledImage>& cells, int columns, int cell_width);

// `name` with every character but letters, digits, '-' and '.' turned into '_', and its leading
// dots and underscores dropped (a set given as ../data/x would otherwise name hidden files).
std::string SafeFileName(const std::string& name);

// Writes `image` as a PNG, making the folder first; the error names the file.
Status WritePng(const std::filesystem::path& file, const cv::Mat& image);

}  // namespace px::eval
