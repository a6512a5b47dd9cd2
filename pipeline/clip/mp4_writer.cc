#include "pipeline/clip/mp4_writer.h"

#include <array>
#include <cmath>
#include <string>

#include "pipeline/clip/bgr_to_yuv420.h"
#include "pipeline/clip/libav_stream_writer.h"

namespace px::clip {

namespace {

constexpr std::array<const char*, 10> kPresets = {
    "ultrafast", "superfast", "veryfast", "faster", "fast", "medium", "slow", "slower", "veryslow", "placebo"};

// libavcodec's libx264 wrapper, writing an MP4 through libavformat. Colour: BGR is converted to
// BT.709 limited-range yuv420p (what phones and browsers assume for untagged HD video, and the
// stream is tagged so), by libswscale.
class LibavMp4Writer final : public Mp4Writer {
 public:
  LibavMp4Writer(const std::filesystem::path& path, int width, int height)
      : Mp4Writer(ClipFormat::kMp4, path, width, height) {}

  Status Init(const Mp4Options& options) {
    const AVRational frame_rate = av_d2q(options.fps, 100000);
    LibavStreamSpec spec;
    spec.muxer = "mp4";
    spec.encoder = "libx264";
    spec.pixel_format = AV_PIX_FMT_YUV420P;
    spec.frame_rate = frame_rate;
    spec.time_base = av_inv_q(frame_rate);  // one tick per frame: constant frame rate
    spec.encoder_options = {{"preset", options.preset}, {"crf", std::to_string(options.crf)}};
    // faststart: after the last frame the muxer moves the index (moov) before the media data
    // (mdat), so players can start before the whole file has arrived.
    spec.muxer_options = {{"movflags", "+faststart"}};
    spec.configure = [fps = options.fps](AVCodecContext* codec) {
      codec->gop_size = std::max(1, static_cast<int>(std::lround(2 * fps)));  // a keyframe every 2 s
      // One encoder thread: the clip is encoded beside the renderer, which keeps both cores busy;
      // x264's own frame threads (auto: 1.5 a core) only compete with it for them
      // (render_clip_benchmark times the whole clip either way).
      codec->thread_count = 1;
      codec->color_range = AVCOL_RANGE_MPEG;
      codec->colorspace = AVCOL_SPC_BT709;
      codec->color_primaries = AVCOL_PRI_BT709;
      codec->color_trc = AVCOL_TRC_BT709;
    };
    PX_ASSIGN_OR_RETURN(stream_, LibavStreamWriter::Open(path(), StoredWidth(), StoredHeight(), spec));
    return converter_.Init(StoredWidth(), StoredHeight(), BgrToYuv420::Matrix::kBt709);
  }

  // yuv420p subsamples chroma by two: odd sizes lose their last column or row.
  int StoredWidth() const override { return width() & ~1; }
  int StoredHeight() const override { return height() & ~1; }

 protected:
  Status WriteFrame(const cv::Mat& bgr, int index) override {
    PX_ASSIGN_OR_RETURN(AVFrame * frame, stream_->WritableFrame());
    frame->color_range = AVCOL_RANGE_MPEG;
    frame->colorspace = AVCOL_SPC_BT709;
    converter_.Convert(bgr, frame);
    return stream_->WriteFrame(index);
  }
  Status FinishClip() override { return stream_->Finish(); }

 private:
  std::unique_ptr<LibavStreamWriter> stream_;
  BgrToYuv420 converter_;
};

}  // namespace

Status Mp4Options::Validate() const {
  if (!(fps > 0 && fps <= 240))
    return InvalidArgumentError("clip.fps: " + std::to_string(fps) + " is outside (0, 240]");
  if (crf < 0 || crf > 51) return InvalidArgumentError("clip.crf: " + std::to_string(crf) + " is outside [0, 51]");
  for (const char* known : kPresets) {
    if (preset == known) return OkStatus();
  }
  return InvalidArgumentError("clip.preset: \"" + preset + "\" is not an x264 preset (ultrafast .. placebo)");
}

StatusOr<std::unique_ptr<Mp4Writer>> Mp4Writer::Open(const std::filesystem::path& path,
                                                     int width,
                                                     int height,
                                                     const Mp4Options& options) {
  PX_RETURN_IF_ERROR(options.Validate());
  PX_RETURN_IF_ERROR(CheckClipSize(path, width, height, 2, 16384));
  auto writer = std::make_unique<LibavMp4Writer>(path, width, height);
  PX_RETURN_IF_ERROR(writer->Init(options));
  return std::unique_ptr<Mp4Writer>(std::move(writer));
}

}  // namespace px::clip
