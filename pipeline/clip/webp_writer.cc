#include "pipeline/clip/webp_writer.h"

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <string>

#include "pipeline/clip/bgr_to_yuv420.h"
#include "pipeline/clip/libav_stream_writer.h"

namespace px::clip {
namespace {

// Lossy frames go in as BT.601 yuv420p (WebP's own colour space, so libwebp does no second
// conversion); lossless frames as BGRA, which libwebp keeps exactly.
class WebpWriter final : public ClipWriter {
 public:
  WebpWriter(const std::filesystem::path& path, int width, int height, const ClipOptions& options)
      : ClipWriter(ClipFormat::kWebp, path, width, height), fps_(options.fps), lossless_(options.webp_lossless) {}

  Status Init(const ClipOptions& options) {
    LibavStreamSpec spec;
    spec.muxer = "webp";
    spec.encoder = "libwebp_anim";
    spec.pixel_format = lossless_ ? AV_PIX_FMT_BGRA : AV_PIX_FMT_YUV420P;
    spec.time_base = {1, 1000};  // WebP frame durations are in milliseconds
    spec.frame_rate = av_d2q(options.fps, 100000);
    spec.encoder_options = {{"lossless", lossless_ ? "1" : "0"}, {"quality", std::to_string(options.webp_quality)}};
    // The ANIM chunk's loop count: 0 = forever, n = played n times (the muxer's default is 1).
    spec.muxer_options = {{"loop", std::to_string(options.loop_count)}};
    PX_ASSIGN_OR_RETURN(stream_, LibavStreamWriter::Open(path(), width(), height(), spec));
    if (!lossless_) return converter_.Init(width(), height(), BgrToYuv420::Matrix::kBt601);
    return OkStatus();
  }

 protected:
  Status WriteFrame(const cv::Mat& bgr, int index) override {
    PX_ASSIGN_OR_RETURN(AVFrame * frame, stream_->WritableFrame());
    if (lossless_) {
      cv::Mat bgra(height(), width(), CV_8UC4, frame->data[0], static_cast<size_t>(frame->linesize[0]));
      cv::cvtColor(bgr, bgra, cv::COLOR_BGR2BGRA);
    } else {
      converter_.Convert(bgr, frame);
    }
    return stream_->WriteFrame(std::llround(index * 1000.0 / fps_));
  }

  Status FinishClip() override { return stream_->Finish(); }

 private:
  double fps_;
  bool lossless_;
  std::unique_ptr<LibavStreamWriter> stream_;
  BgrToYuv420 converter_;
};

}  // namespace

StatusOr<std::unique_ptr<ClipWriter>> OpenWebpWriter(const std::filesystem::path& path,
                                                     int width,
                                                     int height,
                                                     const ClipOptions& options) {
  PX_RETURN_IF_ERROR(CheckClipSize(path, width, height, 1, 16383));  // WebP's limit
  auto writer = std::make_unique<WebpWriter>(path, width, height, options);
  PX_RETURN_IF_ERROR(writer->Init(options));
  return std::unique_ptr<ClipWriter>(std::move(writer));
}

}  // namespace px::clip
