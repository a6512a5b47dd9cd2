#include "eval/datasets/image_folder.h"

#include <algorithm>
#include <cctype>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "pipeline/io/exif.h"

namespace px::eval {

namespace {

std::string Lower(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

}  // namespace

StatusOr<std::vector<FolderImage>> LoadImageFolder(const std::filesystem::path& dir, int max_side_px) {
  std::error_code ec;
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    const std::string extension = Lower(entry.path().extension().string());
    if (extension == ".jpg" || extension == ".jpeg" || extension == ".png") files.push_back(entry.path());
  }
  if (ec) return NotFoundError(dir.string() + ": " + ec.message());
  if (files.empty()) return NotFoundError(dir.string() + ": no JPEG or PNG images");
  std::sort(files.begin(), files.end());
  std::vector<FolderImage> images;
  for (const std::filesystem::path& file : files) {
    FolderImage image;
    image.name = file.filename().string();
    // IMREAD_COLOR applies the EXIF orientation, so the image is upright.
    cv::Mat bgr = cv::imread(file.string(), cv::IMREAD_COLOR);
    if (bgr.empty()) return DataLossError(file.string() + ": cannot decode the image");
    const double scale = std::min(1.0, static_cast<double>(max_side_px) / std::max(bgr.cols, bgr.rows));
    if (scale < 1.0) cv::resize(bgr, bgr, cv::Size(), scale, scale, cv::INTER_AREA);
    image.bgr = bgr;
    const std::string extension = Lower(file.extension().string());
    if (extension != ".png") {
      StatusOr<ExifInfo> exif = ReadJpegExif(file);
      if (exif.ok()) image.focal_px = exif->FocalPx(bgr.cols, bgr.rows, &image.focal_source);
    }
    images.push_back(std::move(image));
  }
  return images;
}

}  // namespace px::eval
