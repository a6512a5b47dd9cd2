// Test helper for device/ tests: opens a video with libavformat and counts its packets, so a
// test can check what a clip holds without trusting the writer that made it.
#pragma once

#include <filesystem>
#include <string>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
}

namespace px::device {

struct ProbedVideo {
  bool opened = false;
  std::string format;  // "mov,mp4,m4a,3gp,3g2,mj2"
  std::string codec;   // "h264"
  int width = 0;
  int height = 0;
  int frames = 0;  // video packets (one per frame for H.264 without B-frame reordering loss)
};

inline ProbedVideo ProbeVideo(const std::filesystem::path& path) {
  ProbedVideo probed;
  AVFormatContext* context = nullptr;
  if (avformat_open_input(&context, path.c_str(), nullptr, nullptr) != 0) return probed;
  if (avformat_find_stream_info(context, nullptr) < 0) {
    avformat_close_input(&context);
    return probed;
  }
  const int stream = av_find_best_stream(context, AVMEDIA_TYPE_VIDEO, -1, -1, nullptr, 0);
  if (stream >= 0) {
    const AVCodecParameters* parameters = context->streams[stream]->codecpar;
    probed.opened = true;
    probed.format = context->iformat->name;
    probed.codec = avcodec_get_name(parameters->codec_id);
    probed.width = parameters->width;
    probed.height = parameters->height;
    AVPacket* packet = av_packet_alloc();
    while (av_read_frame(context, packet) >= 0) {
      if (packet->stream_index == stream) ++probed.frames;
      av_packet_unref(packet);
    }
    av_packet_free(&packet);
  }
  avformat_close_input(&context);
  return probed;
}

}  // namespace px::device
