#include "pipeline/clip/mp4_writer.h"

#include <array>
#include <cstdint>
#include <cmath>
#include <string>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/log.h>
#include <libavutil/opt.h>
#include <libswscale/swscale.h>
}

namespace px::clip {

namespace {

constexpr std::array<const char*, 10> kPresets = {"ultrafast", "superfast", "veryfast", "faster", "fast",
                                                  "medium",    "slow",      "slower",   "veryslow", "placebo"};

std::string AvErrorText(int error) {
  char text[AV_ERROR_MAX_STRING_SIZE] = {0};
  av_strerror(error, text, sizeof(text));
  return text;
}

Status AvError(const std::string& what, int error) {
  const std::string message = what + ": " + AvErrorText(error);
  if (error == AVERROR(ENOSPC)) return ResourceExhaustedError(message);
  if (error == AVERROR(ENOENT)) return NotFoundError(message);
  return InternalError(message);
}

// libavcodec's libx264 wrapper, writing an MP4 through libavformat. Colour: BGR is converted to
// BT.709 limited-range yuv420p (what phones and browsers assume for untagged HD video, and the
// stream is tagged so), by libswscale.
class LibavMp4Writer : public Mp4Writer {
 public:
  LibavMp4Writer(std::filesystem::path path, int width, int height)
      : path_(std::move(path)), width_(width), height_(height), encoded_width_(width & ~1), encoded_height_(height & ~1) {}

  ~LibavMp4Writer() override {
    // Without Finish the file stays incomplete (no index); the caller deletes its temporary.
    if (format_ != nullptr && format_->pb != nullptr) avio_closep(&format_->pb);
    sws_freeContext(sws_);
    av_frame_free(&frame_);
    av_packet_free(&packet_);
    avcodec_free_context(&codec_);
    avformat_free_context(format_);
  }

  Status Init(const Mp4Options& options) {
    const std::string name = path_.string();
    int error = avformat_alloc_output_context2(&format_, nullptr, "mp4", name.c_str());
    if (error < 0 || format_ == nullptr) return AvError("clip " + name + ": mp4 muxer", error);
    const AVCodec* encoder = avcodec_find_encoder_by_name("libx264");
    if (encoder == nullptr) return UnavailableError("clip " + name + ": libavcodec has no libx264 encoder");
    stream_ = avformat_new_stream(format_, nullptr);
    codec_ = avcodec_alloc_context3(encoder);
    if (stream_ == nullptr || codec_ == nullptr) return ResourceExhaustedError("clip " + name + ": out of memory");

    const AVRational frame_rate = av_d2q(options.fps, 100000);
    codec_->width = encoded_width_;
    codec_->height = encoded_height_;
    codec_->pix_fmt = AV_PIX_FMT_YUV420P;
    codec_->framerate = frame_rate;
    codec_->time_base = av_inv_q(frame_rate);  // one tick per frame: constant frame rate
    codec_->gop_size = std::max(1, static_cast<int>(std::lround(2 * options.fps)));  // a keyframe every 2 s
    codec_->color_range = AVCOL_RANGE_MPEG;
    codec_->colorspace = AVCOL_SPC_BT709;
    codec_->color_primaries = AVCOL_PRI_BT709;
    codec_->color_trc = AVCOL_TRC_BT709;
    if (format_->oformat->flags & AVFMT_GLOBALHEADER) codec_->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
    error = av_opt_set(codec_->priv_data, "preset", options.preset.c_str(), 0);
    if (error < 0) return AvError("clip " + name + ": x264 preset \"" + options.preset + "\"", error);
    error = av_opt_set_double(codec_->priv_data, "crf", options.crf, 0);
    if (error < 0) return AvError("clip " + name + ": x264 crf " + std::to_string(options.crf), error);
    error = avcodec_open2(codec_, encoder, nullptr);
    if (error < 0) return AvError("clip " + name + ": opening libx264", error);

    error = avcodec_parameters_from_context(stream_->codecpar, codec_);
    if (error < 0) return AvError("clip " + name + ": stream parameters", error);
    stream_->time_base = codec_->time_base;
    stream_->avg_frame_rate = frame_rate;
    stream_->r_frame_rate = frame_rate;

    error = avio_open(&format_->pb, name.c_str(), AVIO_FLAG_WRITE);
    if (error < 0) return AvError("clip " + name + ": opening for writing", error);
    AVDictionary* muxer_options = nullptr;
    // faststart: after the last frame the muxer moves the index (moov) before the media data
    // (mdat), so players can start before the whole file has arrived.
    av_dict_set(&muxer_options, "movflags", "+faststart", 0);
    error = avformat_write_header(format_, &muxer_options);
    av_dict_free(&muxer_options);
    if (error < 0) return AvError("clip " + name + ": writing the header", error);

    frame_ = av_frame_alloc();
    packet_ = av_packet_alloc();
    if (frame_ == nullptr || packet_ == nullptr) return ResourceExhaustedError("clip " + name + ": out of memory");
    frame_->format = AV_PIX_FMT_YUV420P;
    frame_->width = encoded_width_;
    frame_->height = encoded_height_;
    frame_->color_range = AVCOL_RANGE_MPEG;
    frame_->colorspace = AVCOL_SPC_BT709;
    error = av_frame_get_buffer(frame_, 0);
    if (error < 0) return AvError("clip " + name + ": frame buffer", error);

    sws_ = sws_getContext(encoded_width_, encoded_height_, AV_PIX_FMT_BGR24, encoded_width_, encoded_height_,
                          AV_PIX_FMT_YUV420P, SWS_BILINEAR, nullptr, nullptr, nullptr);
    if (sws_ == nullptr) return InternalError("clip " + name + ": no BGR24 to yuv420p converter");
    // Full-range RGB in, BT.709 limited-range YUV out.
    const int* bt709 = sws_getCoefficients(SWS_CS_ITU709);
    sws_setColorspaceDetails(sws_, bt709, 1, bt709, 0, 0, 1 << 16, 1 << 16);
    return OkStatus();
  }

  Status Write(const cv::Mat& bgr) override {
    if (finished_) return FailedPreconditionError("clip " + path_.string() + ": Write after Finish");
    if (bgr.type() != CV_8UC3 || bgr.cols != width_ || bgr.rows != height_) {
      return InvalidArgumentError("clip " + path_.string() + ": frame " + std::to_string(frames_written_) + " is " +
                                  std::to_string(bgr.cols) + "x" + std::to_string(bgr.rows) + " type " +
                                  std::to_string(bgr.type()) + ", want " + std::to_string(width_) + "x" +
                                  std::to_string(height_) + " CV_8UC3");
    }
    int error = av_frame_make_writable(frame_);
    if (error < 0) return AvError("clip " + path_.string() + ": frame buffer", error);
    // Odd sizes lose their last column or row: yuv420p subsamples chroma by two.
    cv::Mat cropped = bgr(cv::Rect(0, 0, encoded_width_, encoded_height_));
    // libswscale's SIMD paths want rows on 16-byte boundaries (32 with AVX2); copy rows that are not.
    constexpr size_t kAlignment = 64;
    if (cropped.step[0] % kAlignment != 0 || reinterpret_cast<uintptr_t>(cropped.data) % kAlignment != 0) {
      if (staging_.empty()) {
        const size_t padded = (static_cast<size_t>(encoded_width_) * 3 + kAlignment - 1) / kAlignment * kAlignment;
        staging_buffer_ = cv::Mat(encoded_height_, static_cast<int>(padded), CV_8U);
        staging_ = cv::Mat(encoded_height_, encoded_width_, CV_8UC3, staging_buffer_.data, padded);
      }
      cropped.copyTo(staging_);
      cropped = staging_;
    }
    const uint8_t* source[1] = {cropped.data};
    const int source_stride[1] = {static_cast<int>(cropped.step[0])};
    sws_scale(sws_, source, source_stride, 0, encoded_height_, frame_->data, frame_->linesize);
    frame_->pts = frames_written_;
    PX_RETURN_IF_ERROR(Encode(frame_));
    ++frames_written_;
    return OkStatus();
  }

  Status Finish() override {
    if (finished_) return FailedPreconditionError("clip " + path_.string() + ": Finish called twice");
    finished_ = true;
    PX_RETURN_IF_ERROR(Encode(nullptr));  // drain the encoder's delayed frames
    int error = av_write_trailer(format_);
    if (error < 0) return AvError("clip " + path_.string() + ": writing the index", error);
    error = avio_closep(&format_->pb);
    if (error < 0) return AvError("clip " + path_.string() + ": closing", error);
    if (frames_written_ == 0) return FailedPreconditionError("clip " + path_.string() + ": no frames were written");
    return OkStatus();
  }

  int FramesWritten() const override { return frames_written_; }

 private:
  // Sends one frame (nullptr: end of stream) and writes every packet the encoder releases.
  Status Encode(const AVFrame* frame) {
    int error = avcodec_send_frame(codec_, frame);
    if (error < 0) return AvError("clip " + path_.string() + ": encoding frame " + std::to_string(frames_written_), error);
    while (true) {
      error = avcodec_receive_packet(codec_, packet_);
      if (error == AVERROR(EAGAIN) || error == AVERROR_EOF) return OkStatus();
      if (error < 0) return AvError("clip " + path_.string() + ": encoding", error);
      av_packet_rescale_ts(packet_, codec_->time_base, stream_->time_base);
      packet_->stream_index = stream_->index;
      error = av_interleaved_write_frame(format_, packet_);  // takes the packet's data, resets it
      if (error < 0) return AvError("clip " + path_.string() + ": writing", error);
    }
  }

  std::filesystem::path path_;
  int width_;
  int height_;
  int encoded_width_;
  int encoded_height_;
  AVFormatContext* format_ = nullptr;
  AVStream* stream_ = nullptr;  // owned by format_
  AVCodecContext* codec_ = nullptr;
  AVFrame* frame_ = nullptr;
  AVPacket* packet_ = nullptr;
  SwsContext* sws_ = nullptr;
  cv::Mat staging_buffer_;  // owns the aligned rows staging_ views
  cv::Mat staging_;
  int frames_written_ = 0;
  bool finished_ = false;
};

}  // namespace

Status Mp4Options::Validate() const {
  if (!(fps > 0 && fps <= 240)) return InvalidArgumentError("clip.fps: " + std::to_string(fps) + " is outside (0, 240]");
  if (crf < 0 || crf > 51) return InvalidArgumentError("clip.crf: " + std::to_string(crf) + " is outside [0, 51]");
  for (const char* known : kPresets) {
    if (preset == known) return OkStatus();
  }
  return InvalidArgumentError("clip.preset: \"" + preset + "\" is not an x264 preset (ultrafast .. placebo)");
}

StatusOr<std::unique_ptr<Mp4Writer>> Mp4Writer::Open(const std::filesystem::path& path, int width, int height,
                                                     const Mp4Options& options) {
  PX_RETURN_IF_ERROR(options.Validate());
  if (width < 2 || height < 2 || width > 16384 || height > 16384) {
    return InvalidArgumentError("clip " + path.string() + ": frame size " + std::to_string(width) + "x" +
                                std::to_string(height) + " is outside 2x2 .. 16384x16384");
  }
  // libx264 reports its settings at info level on every open; keep stderr for warnings.
  if (av_log_get_level() == AV_LOG_INFO) av_log_set_level(AV_LOG_WARNING);
  auto writer = std::make_unique<LibavMp4Writer>(path, width, height);
  PX_RETURN_IF_ERROR(writer->Init(options));
  return std::unique_ptr<Mp4Writer>(std::move(writer));
}

}  // namespace px::clip
