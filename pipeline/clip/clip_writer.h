// Clip output: rendered BGR frames streamed into one of the clip formats, never held in memory
// as a whole clip. Formats (README.md in this folder):
//   mp4   H.264 in MP4 (yuv420p, BT.709, +faststart), CRF settable: what phones and browsers play
//   gif   animated GIF, looping: an adaptive 255-colour palette (median cut), ordered dithering
//   webp  animated WebP, looping: lossy (quality settable) or lossless
//   png   a folder of lossless PNG frames (frame_00000.png, ...): for editing or re-encoding
// The clip is written at the size of the frames given (the pipeline's output size: no cap here).
// The caller owns atomicity: write to a temporary name (a temporary folder for png), then rename.
#pragma once

#include <filesystem>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <string_view>

#include "pipeline/core/status.h"

namespace px::clip {

enum class ClipFormat { kMp4, kGif, kWebp, kPng };

std::string_view ClipFormatName(ClipFormat format);  // "mp4", "gif", "webp", "png"
StatusOr<ClipFormat> ParseClipFormat(std::string_view name);
// The clip's file-name extension: ".mp4", ".gif", ".webp"; "" for png, whose clip is a folder.
std::string_view ClipFormatExtension(ClipFormat format);

struct ClipOptions {
  ClipFormat format = ClipFormat::kMp4;
  double fps = 30.0;  // frames per second, (0, 240]; GIF stores delays in 1/100 s
  // mp4
  int crf = 20;                     // x264 constant rate factor, [0, 51]; lower is better and larger
  std::string preset = "veryfast";  // x264 preset: ultrafast .. placebo
  // gif, webp
  int loop_count = 0;  // times the animation plays, [0, 65535]; 0 = forever
  // webp
  int webp_quality = 80;       // lossy quality, [0, 100]; higher is better and larger
  bool webp_lossless = false;  // lossless instead (webp_quality then sets the effort)
  // gif
  bool gif_dither = true;  // ordered (Bayer 4x4) dithering against palette banding
  // png
  int png_compression = 1;  // zlib level, [0, 9]; 1 is fast and still lossless

  // Errors name the field as the daemon config does ("clip.crf: 60 is outside [0, 51]").
  Status Validate() const;
};

// The frames of one clip, in order. Write checks each frame; Finish completes the file.
class ClipWriter {
 public:
  virtual ~ClipWriter() = default;
  ClipWriter(const ClipWriter&) = delete;
  ClipWriter& operator=(const ClipWriter&) = delete;

  // `bgr` is CV_8UC3 of the size given to Open. INVALID_ARGUMENT names the frame and its size.
  Status Write(const cv::Mat& bgr);
  // Flushes and completes the clip. Must be called once; FAILED_PRECONDITION when no frame was
  // written (the file is then left incomplete for the caller to remove).
  Status Finish();
  int FramesWritten() const { return frames_written_; }
  ClipFormat format() const { return format_; }
  // The size frames must have, and the size stored (MP4 crops odd sizes by one pixel).
  int width() const { return width_; }
  int height() const { return height_; }
  virtual int StoredWidth() const { return width_; }
  virtual int StoredHeight() const { return height_; }

 protected:
  ClipWriter(ClipFormat format, std::filesystem::path path, int width, int height);
  virtual Status WriteFrame(const cv::Mat& bgr, int index) = 0;  // checked frame `index`
  virtual Status FinishClip() = 0;
  const std::filesystem::path& path() const { return path_; }

 private:
  ClipFormat format_;
  std::filesystem::path path_;
  int width_;
  int height_;
  int frames_written_ = 0;
  bool finished_ = false;
};

// Opens a writer of options.format on `path` for width x height frames. INVALID_ARGUMENT for bad
// options or a size the format cannot hold; the encoder's or the file system's error otherwise.
StatusOr<std::unique_ptr<ClipWriter>> OpenClipWriter(const std::filesystem::path& path,
                                                     int width,
                                                     int height,
                                                     const ClipOptions& options);

// For the format writers: INVALID_ARGUMENT unless min_size <= width, height <= max_size.
Status CheckClipSize(const std::filesystem::path& path, int width, int height, int min_size, int max_size);

}  // namespace px::clip
