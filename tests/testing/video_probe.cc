#include "tests/testing/video_probe.h"

#include <cstdint>
#include <fstream>
#include <opencv2/imgproc.hpp>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/imgutils.h>
#include <libswscale/swscale.h>
}

namespace px::testing {
namespace {

std::string AvError(int code) {
  char text[AV_ERROR_MAX_STRING_SIZE] = {};
  av_strerror(code, text, sizeof(text));
  return text;
}

// Walks the top-level ISO-BMFF boxes and reports whether 'moov' comes before 'mdat'.
bool MoovBeforeMdat(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  uint64_t offset = 0;
  const uint64_t size = std::filesystem::file_size(path);
  while (offset + 8 <= size) {
    unsigned char header[16];
    in.seekg(static_cast<std::streamoff>(offset));
    if (!in.read(reinterpret_cast<char*>(header), 8)) return false;
    uint64_t box_size =
        (uint64_t{header[0]} << 24) | (uint64_t{header[1]} << 16) | (uint64_t{header[2]} << 8) | uint64_t{header[3]};
    const std::string type(reinterpret_cast<char*>(header + 4), 4);
    if (type == "moov") return true;
    if (type == "mdat") return false;
    if (box_size == 1) {
      if (!in.read(reinterpret_cast<char*>(header + 8), 8)) return false;
      box_size = 0;
      for (int i = 8; i < 16; ++i) box_size = (box_size << 8) | header[i];
    }
    if (box_size < 8) return false;
    offset += box_size;
  }
  return false;
}

cv::Mat ToBgr(const AVFrame* frame, SwsContext** sws) {
  *sws = sws_getCachedContext(*sws,
                              frame->width,
                              frame->height,
                              static_cast<AVPixelFormat>(frame->format),
                              frame->width,
                              frame->height,
                              AV_PIX_FMT_BGR24,
                              SWS_BILINEAR,
                              nullptr,
                              nullptr,
                              nullptr);
  cv::Mat bgr(frame->height, frame->width, CV_8UC3);
  uint8_t* dst[1] = {bgr.data};
  int dst_stride[1] = {static_cast<int>(bgr.step)};
  sws_scale(*sws, frame->data, frame->linesize, 0, frame->height, dst, dst_stride);
  return bgr;
}

}  // namespace

StatusOr<VideoProbe> ProbeVideo(const std::filesystem::path& path) {
  AVFormatContext* format = nullptr;
  int rc = avformat_open_input(&format, path.c_str(), nullptr, nullptr);
  if (rc < 0) return NotFoundError(path.string() + ": " + AvError(rc));
  VideoProbe probe;
  Status status;
  AVCodecContext* codec = nullptr;
  AVPacket* packet = av_packet_alloc();
  AVFrame* frame = av_frame_alloc();
  SwsContext* sws = nullptr;
  do {
    if ((rc = avformat_find_stream_info(format, nullptr)) < 0) {
      status = DataLossError(path.string() + ": no stream info: " + AvError(rc));
      break;
    }
    const int stream = av_find_best_stream(format, AVMEDIA_TYPE_VIDEO, -1, -1, nullptr, 0);
    if (stream < 0) {
      status = DataLossError(path.string() + ": no video stream");
      break;
    }
    const AVStream* video = format->streams[stream];
    const AVCodec* decoder = avcodec_find_decoder(video->codecpar->codec_id);
    codec = avcodec_alloc_context3(decoder);
    avcodec_parameters_to_context(codec, video->codecpar);
    if ((rc = avcodec_open2(codec, decoder, nullptr)) < 0) {
      status = InternalError("cannot open decoder: " + AvError(rc));
      break;
    }
    probe.container = format->iformat->name;
    probe.codec = decoder->name;
    probe.pixel_format = av_get_pix_fmt_name(static_cast<AVPixelFormat>(video->codecpar->format));
    probe.width = video->codecpar->width;
    probe.height = video->codecpar->height;
    probe.fps = av_q2d(video->avg_frame_rate);
    probe.duration_s = format->duration > 0 ? static_cast<double>(format->duration) / AV_TIME_BASE : 0.0;
    auto drain = [&]() {
      while (avcodec_receive_frame(codec, frame) == 0) {
        probe.last_frame = ToBgr(frame, &sws);
        if (probe.frames_decoded == 0) probe.first_frame = probe.last_frame.clone();
        ++probe.frames_decoded;
      }
    };
    while (av_read_frame(format, packet) >= 0) {
      if (packet->stream_index == stream) {
        avcodec_send_packet(codec, packet);
        drain();
      }
      av_packet_unref(packet);
    }
    avcodec_send_packet(codec, nullptr);
    drain();
  } while (false);
  sws_freeContext(sws);
  av_frame_free(&frame);
  av_packet_free(&packet);
  avcodec_free_context(&codec);
  avformat_close_input(&format);
  if (!status.ok()) return status;
  probe.moov_before_mdat = MoovBeforeMdat(path);
  return probe;
}

}  // namespace px::testing
