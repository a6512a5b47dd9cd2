#include "sim/replay/import_images.h"

#include <algorithm>
#include <cctype>
#include <string>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "pipeline/core/exif.h"
#include "pipeline/core/pixel_format.h"

namespace px {

namespace {

std::string LowerExtension(const std::filesystem::path& file) {
  std::string extension = file.extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return extension;
}

bool IsJpeg(const std::filesystem::path& file) {
  const std::string extension = LowerExtension(file);
  return extension == ".jpg" || extension == ".jpeg";
}

bool IsImage(const std::filesystem::path& file) { return IsJpeg(file) || LowerExtension(file) == ".png"; }

}  // namespace

StatusOr<std::vector<std::filesystem::path>> ListImages(const std::vector<std::filesystem::path>& inputs) {
  std::vector<std::filesystem::path> files;
  for (const std::filesystem::path& input : inputs) {
    std::error_code ec;
    if (std::filesystem::is_directory(input, ec)) {
      std::vector<std::filesystem::path> found;
      for (const auto& entry : std::filesystem::directory_iterator(input, ec)) {
        if (entry.is_regular_file() && IsImage(entry.path())) found.push_back(entry.path());
      }
      if (ec) return NotFoundError(input.string() + ": " + ec.message());
      if (found.empty()) return NotFoundError(input.string() + ": no JPEG or PNG images in the folder");
      std::sort(found.begin(), found.end());
      files.insert(files.end(), found.begin(), found.end());
    } else if (std::filesystem::is_regular_file(input, ec)) {
      if (!IsImage(input)) return InvalidArgumentError(input.string() + ": not a JPEG or PNG file (by its name)");
      files.push_back(input);
    } else {
      return NotFoundError(input.string() + ": no such file or folder");
    }
  }
  return files;
}

StatusOr<Recording> RecordingFromImages(const std::vector<std::filesystem::path>& files,
                                        std::vector<std::string>* warnings) {
  if (files.size() < 2) {
    return FailedPreconditionError("an image set needs at least 2 photos from different places, got " +
                                   std::to_string(files.size()));
  }
  Recording recording;
  recording.source.model = "import";
  recording.source.kind = FrameSetKind::kImageSet;
  recording.frames.kind = FrameSetKind::kImageSet;
  recording.created_by = "parallax import";
  for (size_t i = 0; i < files.size(); ++i) {
    const std::filesystem::path& file = files[i];
    // IMREAD_COLOR turns the image upright by its EXIF orientation, which FocalPx expects.
    cv::Mat bgr = cv::imread(file.string(), cv::IMREAD_COLOR);
    if (bgr.empty()) return DataLossError(file.string() + ": cannot be decoded as an image");
    Frame frame;
    PX_ASSIGN_OR_RETURN(frame.image, FromBgr(bgr, PixelFormat::kRgb888));
    frame.sequence = i;
    if (IsJpeg(file)) {
      StatusOr<ExifInfo> exif = ReadJpegExif(file);
      if (exif.ok()) {
        frame.focal_length_px = exif->FocalPx(bgr.cols, bgr.rows, &frame.focal_length_source);
      } else {
        warnings->push_back(file.string() + ": EXIF unreadable (" + exif.status().message() +
                            "); its focal length will be self-calibrated");
      }
    }
    recording.frames.frames.push_back(std::move(frame));
  }
  return recording;
}

}  // namespace px
