#include "capture/import_images.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <opencv2/imgproc.hpp>
#include <string>

#include "capture/animation_frames.h"
#include "capture/mpo.h"
#include "pipeline/core/pixel_format.h"
#include "pipeline/io/exif.h"
#include "pipeline/io/image_file.h"

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

bool IsMpo(const std::filesystem::path& file) { return LowerExtension(file) == ".mpo"; }

bool IsAnimation(const std::filesystem::path& file) {
  const std::string extension = LowerExtension(file);
  return extension == ".gif" || extension == ".webp";
}

bool IsImage(const std::filesystem::path& file) { return IsStillPhotoName(file) || IsMpo(file) || IsAnimation(file); }

// One photo file as a frame: upright by its EXIF orientation (IMREAD_COLOR, which FocalPx
// expects), with a JPEG's EXIF focal length (unknown, and said in `warnings`, when unreadable).
StatusOr<Frame> PhotoFrame(const std::filesystem::path& file, std::vector<std::string>* warnings) {
  PX_ASSIGN_OR_RETURN(std::vector<uint8_t> bytes, ReadImageFileBytes(file));
  PX_ASSIGN_OR_RETURN(const cv::Mat bgr, DecodeImageBytes(bytes, file.string()));
  Frame frame;
  PX_ASSIGN_OR_RETURN(frame.image, FromBgr(bgr, PixelFormat::kRgb888));
  if (IsJpeg(file)) {
    StatusOr<ExifInfo> exif = ParseJpegExif(bytes);
    if (exif.ok()) {
      frame.focal_length_px = exif->FocalPx(bgr.cols, bgr.rows, &frame.focal_length_source);
    } else {
      warnings->push_back(file.string() + ": EXIF unreadable (" + exif.status().message() +
                          "); its focal length will be self-calibrated");
    }
    frame.jpeg = std::move(bytes);  // a recording keeps the photo as it came
  }
  return frame;
}

// One frame per image of an MPO file, each with the focal length of its own EXIF.
Status AddMpoFrames(const std::filesystem::path& file, std::vector<std::string>* warnings, Recording* recording) {
  PX_ASSIGN_OR_RETURN(std::vector<uint8_t> bytes, ReadImageFileBytes(file));
  PX_ASSIGN_OR_RETURN(std::vector<std::vector<uint8_t>> images, SplitMpo(bytes, file.string()));
  for (size_t i = 0; i < images.size(); ++i) {
    const std::string name = file.string() + " image " + std::to_string(i);
    PX_ASSIGN_OR_RETURN(const cv::Mat bgr, DecodeImageBytes(images[i], name));
    Frame frame;
    PX_ASSIGN_OR_RETURN(frame.image, FromBgr(bgr, PixelFormat::kRgb888));
    StatusOr<ExifInfo> exif = ParseJpegExif(images[i]);
    if (exif.ok()) {
      frame.focal_length_px = exif->FocalPx(bgr.cols, bgr.rows, &frame.focal_length_source);
    } else {
      warnings->push_back(name + ": EXIF unreadable (" + exif.status().message() +
                          "); its focal length will be self-calibrated");
    }
    frame.jpeg = std::move(images[i]);
    frame.sequence = recording->frames.frames.size();
    recording->frames.frames.push_back(std::move(frame));
  }
  return OkStatus();
}

// One frame per view of an animation (its repeated frames left out).
Status AddAnimationFrames(const std::filesystem::path& file, std::vector<std::string>* warnings, Recording* recording) {
  PX_ASSIGN_OR_RETURN(std::vector<cv::Mat> frames, ReadAnimationFrames(file));
  const std::vector<cv::Mat> views = WithoutRepeatedFrames(frames);
  if (views.size() < frames.size()) {
    warnings->push_back(file.string() + ": " + std::to_string(frames.size() - views.size()) + " of its " +
                        std::to_string(frames.size()) +
                        " frames repeat earlier ones (a back-and-forth loop): left out");
  }
  for (const cv::Mat& bgr : views) {
    Frame frame;
    PX_ASSIGN_OR_RETURN(frame.image, FromBgr(bgr, PixelFormat::kRgb888));
    frame.sequence = recording->frames.frames.size();
    recording->frames.frames.push_back(std::move(frame));
  }
  return OkStatus();
}

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
      if (found.empty()) return NotFoundError(input.string() + ": no images (JPEG, PNG, MPO, GIF, WebP) in the folder");
      std::sort(found.begin(), found.end());
      files.insert(files.end(), found.begin(), found.end());
    } else if (std::filesystem::is_regular_file(input, ec)) {
      if (!IsImage(input))
        return InvalidArgumentError(input.string() + ": not a JPEG, PNG, MPO, GIF or WebP file (by its name)");
      files.push_back(input);
    } else {
      return NotFoundError(input.string() + ": no such file or folder");
    }
  }
  return files;
}

namespace {

// RecordingFromImages, with how many frames each file gave in `frames_per_file`.
StatusOr<Recording> ReadImageSet(const std::vector<std::filesystem::path>& files,
                                 std::vector<std::string>* warnings,
                                 std::vector<size_t>* frames_per_file) {
  const bool holds_views = files.size() == 1 && (IsMpo(files[0]) || IsAnimation(files[0]));
  if (files.size() < 2 && !holds_views) {
    return FailedPreconditionError("an image set needs at least 2 photos from different places, got " +
                                   std::to_string(files.size()));
  }
  Recording recording;
  recording.source.model = "import";
  recording.source.kind = FrameSetKind::kImageSet;
  recording.frames.kind = FrameSetKind::kImageSet;
  recording.created_by = "parallax import";
  for (const std::filesystem::path& file : files) {
    const size_t before = recording.frames.frames.size();
    if (IsMpo(file)) {
      PX_RETURN_IF_ERROR(AddMpoFrames(file, warnings, &recording));
    } else if (IsAnimation(file)) {
      PX_RETURN_IF_ERROR(AddAnimationFrames(file, warnings, &recording));
    } else {
      PX_ASSIGN_OR_RETURN(Frame frame, PhotoFrame(file, warnings));
      frame.sequence = recording.frames.frames.size();
      recording.frames.frames.push_back(std::move(frame));
    }
    frames_per_file->push_back(recording.frames.frames.size() - before);
  }
  if (recording.frames.frames.size() < 2) {
    return FailedPreconditionError(files.front().string() + ": holds " +
                                   std::to_string(recording.frames.frames.size()) +
                                   " view; an image set needs at least 2 from different places");
  }
  return recording;
}

// One JPEG or PNG and nothing else: one viewpoint, so views only as a lattice (a film scan, a
// multi-lens frame, a side-by-side stereo photo).
bool IsLonePhoto(const std::vector<std::filesystem::path>& files) {
  return files.size() == 1 && IsStillPhotoName(files[0]);
}

StatusOr<Recording> LonePhotoAsLattice(const std::filesystem::path& file, std::vector<std::string>* warnings) {
  PX_ASSIGN_OR_RETURN(Recording recording, RecordingFromLatticePhoto(file, LatticeHint{}, warnings));
  warnings->push_back(file.string() +
                      ": one photo, so its views can only be a lattice of tiles in it: found blind when processed "
                      "(parallax import --lattice RxC with the photo named gives its size)");
  return recording;
}

}  // namespace

StatusOr<Recording> RecordingFromImages(const std::vector<std::filesystem::path>& files,
                                        std::vector<std::string>* warnings) {
  if (IsLonePhoto(files)) return LonePhotoAsLattice(files[0], warnings);
  std::vector<size_t> frames_per_file;
  return ReadImageSet(files, warnings, &frames_per_file);
}

StatusOr<Recording> RecordingFromFolder(const std::filesystem::path& folder,
                                        const std::vector<std::filesystem::path>& files,
                                        std::vector<std::string>* warnings) {
  if (IsLonePhoto(files)) return LonePhotoAsLattice(files[0], warnings);
  std::vector<size_t> frames_per_file;
  PX_ASSIGN_OR_RETURN(Recording recording, ReadImageSet(files, warnings, &frames_per_file));
  std::vector<size_t> holding_views;  // the files with several views, by index
  for (size_t i = 0; i < files.size(); ++i) {
    if (frames_per_file[i] >= 2) holding_views.push_back(i);
  }
  if (holding_views.size() < 2) return recording;
  // The first such file's frames alone (it has two or more: still an image set).
  const size_t kept = holding_views.front();
  size_t first_frame = 0;
  for (size_t i = 0; i < kept; ++i) first_frame += frames_per_file[i];
  std::vector<Frame>& frames = recording.frames.frames;
  frames.erase(frames.begin() + first_frame + frames_per_file[kept], frames.end());
  frames.erase(frames.begin(), frames.begin() + first_frame);
  for (size_t i = 0; i < frames.size(); ++i) frames[i].sequence = i;
  std::string left_out;
  for (size_t i = 0; i < files.size(); ++i) {
    if (i == kept) continue;
    left_out += (left_out.empty() ? "" : ", ") + files[i].filename().string() +
                (frames_per_file[i] >= 2 ? " (" + std::to_string(frames_per_file[i]) + " views)" : " (a photo)");
  }
  warnings->push_back(folder.string() + ": " + std::to_string(holding_views.size()) +
                      " of its files hold several views each (MPO files, animations), each a capture of its own; "
                      "the first by name, " +
                      files[kept].filename().string() + ", is taken, and " + left_out +
                      " left out (a clip of each: parallax batch with the files named)");
  return recording;
}

StatusOr<Recording> RecordingFromLatticePhoto(const std::filesystem::path& file,
                                              const LatticeHint& hint,
                                              std::vector<std::string>* warnings) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(file, error)) return NotFoundError(file.string() + ": no such file");
  PX_ASSIGN_OR_RETURN(Frame frame, PhotoFrame(file, warnings));
  Recording recording;
  recording.source.model = "import:lattice photo";
  recording.source.kind = FrameSetKind::kLatticeFrame;
  recording.source.lattice = hint;
  recording.frames.kind = FrameSetKind::kLatticeFrame;
  recording.created_by = "parallax import";
  recording.frames.frames.push_back(std::move(frame));
  return recording;
}

bool IsStillPhotoName(const std::filesystem::path& file) { return IsJpeg(file) || LowerExtension(file) == ".png"; }

StatusOr<LatticeHint> ParseLatticeSize(const std::string& text) {
  LatticeHint hint;
  if (text == "auto") return hint;
  int rows = 0, cols = 0;
  char x = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c", &rows, &x, &cols, &extra) != 3 || (x != 'x' && x != 'X') || rows < 1 ||
      cols < 1 || rows > 16 || cols > 16 || rows * cols < 2) {
    return InvalidArgumentError("lattice '" + text +
                                "' is neither auto nor RxC (rows x columns, 1..16 each, 2 tiles at least)");
  }
  hint.rows = rows;
  hint.cols = cols;
  return hint;
}

}  // namespace px
