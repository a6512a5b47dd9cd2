#include "pipeline/clip/libav_stream_writer.h"

extern "C" {
#include <libavutil/log.h>
#include <libavutil/opt.h>
}

namespace px::clip {

Status AvError(const std::string& what, int error) {
  char text[AV_ERROR_MAX_STRING_SIZE] = {0};
  av_strerror(error, text, sizeof(text));
  const std::string message = what + ": " + text;
  if (error == AVERROR(ENOSPC)) return ResourceExhaustedError(message);
  if (error == AVERROR(ENOENT)) return NotFoundError(message);
  return InternalError(message);
}

StatusOr<std::unique_ptr<LibavStreamWriter>> LibavStreamWriter::Open(const std::filesystem::path& path,
                                                                     int width,
                                                                     int height,
                                                                     const LibavStreamSpec& spec) {
  // Encoders report their settings at info level on every open; keep stderr for warnings.
  if (av_log_get_level() == AV_LOG_INFO) av_log_set_level(AV_LOG_WARNING);
  std::unique_ptr<LibavStreamWriter> writer(new LibavStreamWriter());
  writer->path_ = path.string();
  writer->name_ = "clip " + path.string();
  PX_RETURN_IF_ERROR(writer->Init(spec, width, height));
  return writer;
}

LibavStreamWriter::~LibavStreamWriter() {
  // Without Finish the file stays incomplete (no trailer); the caller deletes its temporary.
  if (format_ != nullptr && format_->pb != nullptr) avio_closep(&format_->pb);
  av_frame_free(&frame_);
  av_packet_free(&packet_);
  avcodec_free_context(&codec_);
  avformat_free_context(format_);
}

Status LibavStreamWriter::Init(const LibavStreamSpec& spec, int width, int height) {
  int error = avformat_alloc_output_context2(&format_, nullptr, spec.muxer.c_str(), path_.c_str());
  if (error < 0 || format_ == nullptr) return AvError(name_ + ": " + spec.muxer + " muxer", error);
  const AVCodec* encoder = avcodec_find_encoder_by_name(spec.encoder.c_str());
  if (encoder == nullptr) return UnavailableError(name_ + ": libavcodec has no " + spec.encoder + " encoder");
  stream_ = avformat_new_stream(format_, nullptr);
  codec_ = avcodec_alloc_context3(encoder);
  if (stream_ == nullptr || codec_ == nullptr) return ResourceExhaustedError(name_ + ": out of memory");

  codec_->width = width;
  codec_->height = height;
  codec_->pix_fmt = spec.pixel_format;
  codec_->framerate = spec.frame_rate;
  codec_->time_base = spec.time_base;
  if (format_->oformat->flags & AVFMT_GLOBALHEADER) codec_->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
  if (spec.configure) spec.configure(codec_);
  for (const auto& [key, value] : spec.encoder_options) {
    error = av_opt_set(codec_->priv_data, key.c_str(), value.c_str(), 0);
    if (error < 0) return AvError(name_ + ": " + spec.encoder + " option " + key + "=" + value, error);
  }
  error = avcodec_open2(codec_, encoder, nullptr);
  if (error < 0) return AvError(name_ + ": opening " + spec.encoder, error);

  error = avcodec_parameters_from_context(stream_->codecpar, codec_);
  if (error < 0) return AvError(name_ + ": stream parameters", error);
  stream_->time_base = codec_->time_base;
  stream_->avg_frame_rate = spec.frame_rate;
  stream_->r_frame_rate = spec.frame_rate;

  error = avio_open(&format_->pb, path_.c_str(), AVIO_FLAG_WRITE);
  if (error < 0) return AvError(name_ + ": opening for writing", error);
  AVDictionary* muxer_options = nullptr;
  for (const auto& [key, value] : spec.muxer_options) av_dict_set(&muxer_options, key.c_str(), value.c_str(), 0);
  error = avformat_write_header(format_, &muxer_options);
  const AVDictionaryEntry* unused = av_dict_get(muxer_options, "", nullptr, AV_DICT_IGNORE_SUFFIX);
  const std::string unused_key = unused != nullptr ? unused->key : "";
  av_dict_free(&muxer_options);
  if (error < 0) return AvError(name_ + ": writing the header", error);
  if (!unused_key.empty()) return InternalError(name_ + ": the " + spec.muxer + " muxer has no option " + unused_key);

  frame_ = av_frame_alloc();
  packet_ = av_packet_alloc();
  if (frame_ == nullptr || packet_ == nullptr) return ResourceExhaustedError(name_ + ": out of memory");
  frame_->format = spec.pixel_format;
  frame_->width = width;
  frame_->height = height;
  error = av_frame_get_buffer(frame_, 0);
  if (error < 0) return AvError(name_ + ": frame buffer", error);
  return OkStatus();
}

StatusOr<AVFrame*> LibavStreamWriter::WritableFrame() {
  const int error = av_frame_make_writable(frame_);
  if (error < 0) return AvError(name_ + ": frame buffer", error);
  return frame_;
}

Status LibavStreamWriter::WriteFrame(int64_t pts) {
  frame_->pts = pts;
  PX_RETURN_IF_ERROR(Encode(frame_));
  ++frames_sent_;
  return OkStatus();
}

Status LibavStreamWriter::Finish() {
  PX_RETURN_IF_ERROR(Encode(nullptr));  // drain the encoder's delayed frames
  int error = av_write_trailer(format_);
  if (error < 0) return AvError(name_ + ": writing the trailer", error);
  error = avio_closep(&format_->pb);
  if (error < 0) return AvError(name_ + ": closing", error);
  return OkStatus();
}

// Sends one frame (nullptr: end of stream) and writes every packet the encoder releases.
Status LibavStreamWriter::Encode(const AVFrame* frame) {
  int error = avcodec_send_frame(codec_, frame);
  if (error < 0) return AvError(name_ + ": encoding frame " + std::to_string(frames_sent_), error);
  while (true) {
    error = avcodec_receive_packet(codec_, packet_);
    if (error == AVERROR(EAGAIN) || error == AVERROR_EOF) return OkStatus();
    if (error < 0) return AvError(name_ + ": encoding", error);
    av_packet_rescale_ts(packet_, codec_->time_base, stream_->time_base);
    packet_->stream_index = stream_->index;
    error = av_interleaved_write_frame(format_, packet_);  // takes the packet's data, resets it
    if (error < 0) return AvError(name_ + ": writing", error);
  }
}

}  // namespace px::clip
