// One encoded video stream muxed into a file through libavcodec/libavformat: the part every
// libav-based clip format shares (MP4/H.264, GIF, animated WebP). The format-specific writer
// fills frame() in the encoder's pixel format and calls WriteFrame.
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
}

#include "pipeline/core/status.h"

namespace px::clip {

struct LibavStreamSpec {
  std::string muxer;                             // libavformat muxer: "mp4", "gif", "webp"
  std::string encoder;                           // libavcodec encoder: "libx264", "gif", "libwebp_anim"
  AVPixelFormat pixel_format = AV_PIX_FMT_NONE;  // what frame() holds
  AVRational time_base{1, 30};                   // pts units
  AVRational frame_rate{30, 1};
  // Encoder private options (x264 "preset", "crf"; webp "quality") and muxer options ("movflags",
  // "loop"), set by name; an option the library rejects is an error naming it and its value.
  std::vector<std::pair<std::string, std::string>> encoder_options;
  std::vector<std::pair<std::string, std::string>> muxer_options;
  // Sets anything else on the encoder before it opens (GOP size, colour tags).
  std::function<void(AVCodecContext*)> configure;
};

class LibavStreamWriter {
 public:
  // Opens the muxer on `path` and the encoder for width x height frames. Errors start
  // "clip <path>: ".
  static StatusOr<std::unique_ptr<LibavStreamWriter>> Open(const std::filesystem::path& path,
                                                           int width,
                                                           int height,
                                                           const LibavStreamSpec& spec);
  ~LibavStreamWriter();
  LibavStreamWriter(const LibavStreamWriter&) = delete;
  LibavStreamWriter& operator=(const LibavStreamWriter&) = delete;

  // The frame to fill before WriteFrame, made writable (the encoder may still hold the last one).
  StatusOr<AVFrame*> WritableFrame();
  // Encodes frame() with presentation time `pts` (in time_base units) and writes the packets.
  Status WriteFrame(int64_t pts);
  // Drains the encoder and writes the trailer; then closes the file.
  Status Finish();

 private:
  LibavStreamWriter() = default;
  Status Init(const LibavStreamSpec& spec, int width, int height);
  Status Encode(const AVFrame* frame);

  std::string path_;
  std::string name_;  // "clip <path>", for messages
  AVFormatContext* format_ = nullptr;
  AVStream* stream_ = nullptr;  // owned by format_
  AVCodecContext* codec_ = nullptr;
  AVFrame* frame_ = nullptr;
  AVPacket* packet_ = nullptr;
  int frames_sent_ = 0;
};

// An FFmpeg error code as a Status: ENOSPC is RESOURCE_EXHAUSTED, ENOENT NOT_FOUND, else INTERNAL.
Status AvError(const std::string& what, int error);

}  // namespace px::clip
