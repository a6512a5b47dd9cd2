#include "capture/animation_frames.h"

#include <webp/demux.h>

#include <fstream>
#include <iterator>
#include <memory>
#include <opencv2/imgproc.hpp>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/imgutils.h>
#include <libswscale/swscale.h>
}

#include "pipeline/io/image_file.h"

namespace px {
namespace {

// Animations of more frames than this are not a handful of views.
constexpr size_t kMaxFrames = 256;
// Nor are more pixels in all than one photo may have (ImageDecodeOptions::max_pixels).
const double kMaxDecodedPixels = ImageDecodeOptions{}.max_pixels;
// Nor a canvas larger than this: a wigglegram's frame is a photo of a few megapixels, while the
// decoders keep two whole canvases of 4 bytes a pixel besides the frames (50 MP: about 0.6 GB).
constexpr double kMaxCanvasPixels = 50e6;

bool WithinPixelBudget(const std::vector<cv::Mat>& frames, int width, int height) {
  return static_cast<double>(frames.size() + 1) * width * height <= kMaxDecodedPixels;
}

StatusOr<std::vector<uint8_t>> ReadBytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return NotFoundError(file.string() + ": cannot be opened");
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

bool StartsWith(const std::vector<uint8_t>& bytes, size_t at, const char* text) {
  const size_t n = std::char_traits<char>::length(text);
  return bytes.size() >= at + n && std::equal(text, text + n, bytes.begin() + static_cast<long>(at));
}

StatusOr<std::vector<cv::Mat>> WebpFrames(const std::filesystem::path& file, const std::vector<uint8_t>& bytes) {
  WebPData data = {bytes.data(), bytes.size()};
  WebPAnimDecoderOptions options;
  if (!WebPAnimDecoderOptionsInit(&options)) return InternalError("libwebpdemux: version mismatch");
  options.color_mode = MODE_BGRA;
  std::unique_ptr<WebPAnimDecoder, decltype(&WebPAnimDecoderDelete)> decoder(WebPAnimDecoderNew(&data, &options),
                                                                             &WebPAnimDecoderDelete);
  if (decoder == nullptr) return DataLossError(file.string() + ": a WebP file libwebp cannot read (damaged chunks?)");
  WebPAnimInfo info;
  if (!WebPAnimDecoderGetInfo(decoder.get(), &info)) return DataLossError(file.string() + ": no WebP canvas");
  std::vector<cv::Mat> frames;
  while (WebPAnimDecoderHasMoreFrames(decoder.get()) && frames.size() < kMaxFrames &&
         WithinPixelBudget(frames, static_cast<int>(info.canvas_width), static_cast<int>(info.canvas_height))) {
    uint8_t* canvas = nullptr;
    int timestamp_ms = 0;
    if (!WebPAnimDecoderGetNext(decoder.get(), &canvas, &timestamp_ms)) {
      return DataLossError(file.string() + ": WebP frame " + std::to_string(frames.size()) + " cannot be decoded");
    }
    const cv::Mat bgra(static_cast<int>(info.canvas_height), static_cast<int>(info.canvas_width), CV_8UC4, canvas);
    cv::Mat bgr;
    cv::cvtColor(bgra, bgr, cv::COLOR_BGRA2BGR);
    frames.push_back(bgr);
  }
  return frames;
}

std::string AvError(int code) {
  char text[AV_ERROR_MAX_STRING_SIZE] = {};
  av_strerror(code, text, sizeof(text));
  return text;
}

// A GIF through FFmpeg's demuxer and decoder (which composite each frame onto the canvas).
StatusOr<std::vector<cv::Mat>> GifFrames(const std::filesystem::path& file) {
  AVFormatContext* opened = nullptr;
  int rc = avformat_open_input(&opened, file.c_str(), nullptr, nullptr);
  if (rc < 0) return DataLossError(file.string() + ": FFmpeg cannot read it as a GIF (" + AvError(rc) + ")");
  std::unique_ptr<AVFormatContext, void (*)(AVFormatContext*)> format(
      opened, [](AVFormatContext* f) { avformat_close_input(&f); });
  if ((rc = avformat_find_stream_info(format.get(), nullptr)) < 0) {
    return DataLossError(file.string() + ": no stream in the GIF (" + AvError(rc) + ")");
  }
  const int stream = av_find_best_stream(format.get(), AVMEDIA_TYPE_VIDEO, -1, -1, nullptr, 0);
  if (stream < 0) return DataLossError(file.string() + ": no picture stream in the GIF");
  const AVCodec* decoder = avcodec_find_decoder(format->streams[stream]->codecpar->codec_id);
  if (decoder == nullptr) return DataLossError(file.string() + ": no decoder for its pictures");
  std::unique_ptr<AVCodecContext, void (*)(AVCodecContext*)> codec(avcodec_alloc_context3(decoder),
                                                                   [](AVCodecContext* c) { avcodec_free_context(&c); });
  avcodec_parameters_to_context(codec.get(), format->streams[stream]->codecpar);
  if ((rc = avcodec_open2(codec.get(), decoder, nullptr)) < 0) {
    return InternalError(file.string() + ": cannot open the GIF decoder (" + AvError(rc) + ")");
  }
  std::unique_ptr<AVPacket, void (*)(AVPacket*)> packet(av_packet_alloc(), [](AVPacket* p) { av_packet_free(&p); });
  std::unique_ptr<AVFrame, void (*)(AVFrame*)> frame(av_frame_alloc(), [](AVFrame* f) { av_frame_free(&f); });
  std::unique_ptr<SwsContext, void (*)(SwsContext*)> sws(nullptr, &sws_freeContext);
  std::vector<cv::Mat> frames;
  const auto drain = [&]() -> Status {
    while (avcodec_receive_frame(codec.get(), frame.get()) == 0) {
      if (frame->width <= 0 || frame->height <= 0 || frames.size() >= kMaxFrames ||
          !WithinPixelBudget(frames, frame->width, frame->height)) {
        continue;
      }
      SwsContext* context = sws_getCachedContext(sws.release(),
                                                 frame->width,
                                                 frame->height,
                                                 static_cast<AVPixelFormat>(frame->format),
                                                 frame->width,
                                                 frame->height,
                                                 AV_PIX_FMT_BGR24,
                                                 SWS_POINT,
                                                 nullptr,
                                                 nullptr,
                                                 nullptr);
      sws.reset(context);
      if (context == nullptr)
        return DataLossError(file.string() + ": a GIF frame in a pixel format FFmpeg cannot convert");
      cv::Mat bgr(frame->height, frame->width, CV_8UC3);
      uint8_t* planes[1] = {bgr.data};
      const int strides[1] = {static_cast<int>(bgr.step)};
      sws_scale(context, frame->data, frame->linesize, 0, frame->height, planes, strides);
      frames.push_back(bgr);
    }
    return OkStatus();
  };
  while (av_read_frame(format.get(), packet.get()) >= 0) {
    if (packet->stream_index == stream && avcodec_send_packet(codec.get(), packet.get()) >= 0) {
      const Status drained = drain();
      if (!drained.ok()) return drained;
    }
    av_packet_unref(packet.get());
  }
  avcodec_send_packet(codec.get(), nullptr);
  PX_RETURN_IF_ERROR(drain());
  if (frames.empty()) return DataLossError(file.string() + ": the GIF breaks off before its first frame");
  return frames;
}

}  // namespace

StatusOr<std::vector<cv::Mat>> ReadAnimationFrames(const std::filesystem::path& file) {
  PX_ASSIGN_OR_RETURN(std::vector<uint8_t> bytes, ReadBytes(file));
  // The canvas its header claims, checked before any frame is decoded (image_file.h).
  if (StatusOr<ImageHeaderSize> canvas = ReadImageHeaderSize(bytes); canvas.ok()) {
    const double pixels = static_cast<double>(canvas->width) * static_cast<double>(canvas->height);
    if (pixels > kMaxCanvasPixels) {
      return ResourceExhaustedError(file.string() + ": its header claims a canvas of " + std::to_string(canvas->width) +
                                    "x" + std::to_string(canvas->height) + " pixels, over the limit of " +
                                    std::to_string(static_cast<int64_t>(kMaxCanvasPixels / 1e6)) +
                                    " MP for an animation; refused before decoding");
    }
  }
  if (StartsWith(bytes, 0, "RIFF") && StartsWith(bytes, 8, "WEBP")) return WebpFrames(file, bytes);
  if (StartsWith(bytes, 0, "GIF87a") || StartsWith(bytes, 0, "GIF89a")) return GifFrames(file);
  return DataLossError(file.string() + ": neither a GIF nor a WebP by its first bytes");
}

std::vector<cv::Mat> WithoutRepeatedFrames(const std::vector<cv::Mat>& frames, double levels) {
  std::vector<cv::Mat> kept;
  for (const cv::Mat& frame : frames) {
    bool repeated = false;
    for (const cv::Mat& earlier : kept) {
      if (earlier.size() != frame.size() || earlier.type() != frame.type()) continue;
      cv::Mat difference;
      cv::absdiff(earlier, frame, difference);
      const cv::Scalar mean = cv::mean(difference);
      if ((mean[0] + mean[1] + mean[2]) / 3 <= levels) {
        repeated = true;
        break;
      }
    }
    if (!repeated) kept.push_back(frame);
  }
  return kept;
}

}  // namespace px
