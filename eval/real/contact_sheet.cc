#include "eval/real/contact_sheet.h"

#include <algorithm>
#include <cctype>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace px::eval {
namespace {

constexpr int kLabelHeightPx = 22;
constexpr int kGapPx = 4;

}  // namespace

cv::Mat ContactSheet(const std::vector<LabelledImage>& cells, int columns, int cell_width) {
  if (cells.empty() || columns <= 0 || cell_width <= 0) return cv::Mat();
  int cell_height = 1;
  for (const LabelledImage& cell : cells) {
    if (cell.image.empty()) continue;
    cell_height = std::max(cell_height, cell.image.rows * cell_width / std::max(1, cell.image.cols));
  }
  const int count = static_cast<int>(cells.size());
  const int used_columns = std::min(columns, count);
  const int rows = (count + columns - 1) / columns;
  const int pitch_x = cell_width + kGapPx, pitch_y = cell_height + kLabelHeightPx + kGapPx;
  cv::Mat sheet(rows * pitch_y + kGapPx, used_columns * pitch_x + kGapPx, CV_8UC3, cv::Scalar(40, 40, 40));
  for (int i = 0; i < count; ++i) {
    const int x = kGapPx + (i % columns) * pitch_x, y = kGapPx + (i / columns) * pitch_y;
    const cv::Mat& image = cells[i].image;
    if (!image.empty()) {
      cv::Mat bgr;
      if (image.channels() == 1) {
        cv::cvtColor(image, bgr, cv::COLOR_GRAY2BGR);
      } else {
        bgr = image;
      }
      const int height = std::min(cell_height, image.rows * cell_width / std::max(1, image.cols));
      cv::Mat scaled;
      cv::resize(bgr, scaled, cv::Size(cell_width, std::max(1, height)), 0, 0, cv::INTER_AREA);
      scaled.copyTo(sheet(cv::Rect(x, y, scaled.cols, scaled.rows)));
    }
    cv::putText(sheet,
                cells[i].label,
                cv::Point(x + 2, y + cell_height + kLabelHeightPx - 7),
                cv::FONT_HERSHEY_SIMPLEX,
                0.5,
                cv::Scalar(235, 235, 235),
                1,
                cv::LINE_AA);
  }
  return sheet;
}

std::string SafeFileName(const std::string& name) {
  std::string safe = name;
  for (char& c : safe) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '.') c = '_';
  }
  const size_t first = safe.find_first_not_of("._");
  return first == std::string::npos ? std::string("set") : safe.substr(first);
}

Status WritePng(const std::filesystem::path& file, const cv::Mat& image) {
  std::error_code error;
  std::filesystem::create_directories(file.parent_path(), error);
  if (error) return InternalError(file.parent_path().string() + ": cannot make the folder (" + error.message() + ")");
  bool written = false;
  try {
    written = cv::imwrite(file.string(), image);
  } catch (const cv::Exception& e) {
    return InternalError(file.string() + ": cannot write the PNG (" + e.what() + ")");
  }
  if (!written) return InternalError(file.string() + ": cannot write the PNG");
  return OkStatus();
}

}  // namespace px::eval
