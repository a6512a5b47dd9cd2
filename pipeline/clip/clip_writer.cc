#include "pipeline/clip/clip_writer.h"

#include "pipeline/clip/gif_writer.h"
#include "pipeline/clip/mp4_writer.h"
#include "pipeline/clip/png_sequence_writer.h"
#include "pipeline/clip/webp_writer.h"

namespace px::clip {

namespace {
constexpr ClipFormat kFormats[] = {ClipFormat::kMp4, ClipFormat::kGif, ClipFormat::kWebp, ClipFormat::kPng};
}  // namespace

std::string_view ClipFormatName(ClipFormat format) {
  switch (format) {
    case ClipFormat::kMp4:
      return "mp4";
    case ClipFormat::kGif:
      return "gif";
    case ClipFormat::kWebp:
      return "webp";
    case ClipFormat::kPng:
      return "png";
  }
  return "?";
}

StatusOr<ClipFormat> ParseClipFormat(std::string_view name) {
  for (ClipFormat format : kFormats) {
    if (name == ClipFormatName(format)) return format;
  }
  return InvalidArgumentError("clip.format: \"" + std::string(name) + "\" is not one of mp4, gif, webp, png");
}

std::string_view ClipFormatExtension(ClipFormat format) {
  switch (format) {
    case ClipFormat::kMp4:
      return ".mp4";
    case ClipFormat::kGif:
      return ".gif";
    case ClipFormat::kWebp:
      return ".webp";
    case ClipFormat::kPng:
      return "";
  }
  return "";
}

Status ClipOptions::Validate() const {
  PX_RETURN_IF_ERROR((Mp4Options{fps, crf, preset}.Validate()));
  if (loop_count < 0 || loop_count > 65535) {
    return InvalidArgumentError("clip.loop_count: " + std::to_string(loop_count) + " is outside [0, 65535]");
  }
  if (webp_quality < 0 || webp_quality > 100) {
    return InvalidArgumentError("clip.webp_quality: " + std::to_string(webp_quality) + " is outside [0, 100]");
  }
  if (png_compression < 0 || png_compression > 9) {
    return InvalidArgumentError("clip.png_compression: " + std::to_string(png_compression) + " is outside [0, 9]");
  }
  return OkStatus();
}

ClipWriter::ClipWriter(ClipFormat format, std::filesystem::path path, int width, int height)
    : format_(format), path_(std::move(path)), width_(width), height_(height) {}

Status ClipWriter::Write(const cv::Mat& bgr) {
  if (finished_) return FailedPreconditionError("clip " + path_.string() + ": Write after Finish");
  if (bgr.type() != CV_8UC3 || bgr.cols != width_ || bgr.rows != height_) {
    return InvalidArgumentError("clip " + path_.string() + ": frame " + std::to_string(frames_written_) + " is " +
                                std::to_string(bgr.cols) + "x" + std::to_string(bgr.rows) + " type " +
                                std::to_string(bgr.type()) + ", want " + std::to_string(width_) + "x" +
                                std::to_string(height_) + " CV_8UC3");
  }
  PX_RETURN_IF_ERROR(WriteFrame(bgr, frames_written_));
  ++frames_written_;
  return OkStatus();
}

Status ClipWriter::Finish() {
  if (finished_) return FailedPreconditionError("clip " + path_.string() + ": Finish called twice");
  finished_ = true;
  // An encoder with nothing to encode fails in its own words; say what happened instead.
  if (frames_written_ == 0) return FailedPreconditionError("clip " + path_.string() + ": no frames were written");
  return FinishClip();
}

Status CheckClipSize(const std::filesystem::path& path, int width, int height, int min_size, int max_size) {
  if (width < min_size || height < min_size || width > max_size || height > max_size) {
    return InvalidArgumentError("clip " + path.string() + ": frame size " + std::to_string(width) + "x" +
                                std::to_string(height) + " is outside " + std::to_string(min_size) + "x" +
                                std::to_string(min_size) + " .. " + std::to_string(max_size) + "x" +
                                std::to_string(max_size));
  }
  return OkStatus();
}

StatusOr<std::unique_ptr<ClipWriter>> OpenClipWriter(const std::filesystem::path& path,
                                                     int width,
                                                     int height,
                                                     const ClipOptions& options) {
  PX_RETURN_IF_ERROR(options.Validate());
  switch (options.format) {
    case ClipFormat::kMp4: {
      PX_ASSIGN_OR_RETURN(auto writer,
                          Mp4Writer::Open(path, width, height, {options.fps, options.crf, options.preset}));
      return std::unique_ptr<ClipWriter>(std::move(writer));
    }
    case ClipFormat::kGif:
      return OpenGifWriter(path, width, height, options);
    case ClipFormat::kWebp:
      return OpenWebpWriter(path, width, height, options);
    case ClipFormat::kPng:
      return OpenPngSequenceWriter(path, width, height, options);
  }
  return InvalidArgumentError("clip.format: unknown");
}

}  // namespace px::clip
