#include "pipeline/clip/gif_writer.h"

#include <cmath>
#include <cstring>
#include <string>

#include "pipeline/clip/libav_stream_writer.h"
#include "pipeline/clip/median_cut_palette.h"

namespace px::clip {
namespace {

// Entry 255 is transparent: the encoder then writes the pixels that did not change since the
// last frame as transparent, which is most of a slow camera move's frame, and LZW packs them.
constexpr int kColours = 255;
constexpr int kTransparentIndex = 255;
// Palettes are built and checked on every 4th pixel in each direction: 1/16 of the frame.
constexpr int kSampleStep = 4;
// A frame that the palette maps more than this many times worse (mean squared error) than the
// frame it was built from gets a new palette (a colour effect fading in, a new region in view).
// The encoder then writes a local palette per frame and loses its frame differencing, so this
// is kept rare.
constexpr double kRebuildErrorRatio = 2.0;
constexpr double kRebuildMinError = 4.0;  // levels^2: below this any palette is good enough

class GifWriter final : public ClipWriter {
 public:
  GifWriter(const std::filesystem::path& path, int width, int height, const ClipOptions& options)
      : ClipWriter(ClipFormat::kGif, path, width, height), fps_(options.fps), dither_(options.gif_dither) {}

  Status Init(const ClipOptions& options) {
    LibavStreamSpec spec;
    spec.muxer = "gif";
    spec.encoder = "gif";
    spec.pixel_format = AV_PIX_FMT_PAL8;
    spec.time_base = {1, 100};  // GIF frame delays are in hundredths of a second
    spec.frame_rate = av_d2q(options.fps, 100000);
    // The muxer's loop: -1 = play once (no NETSCAPE2.0 block), 0 = forever, n = n repeats.
    const int repeats = options.loop_count == 0 ? 0 : options.loop_count == 1 ? -1 : options.loop_count - 1;
    spec.muxer_options = {{"loop", std::to_string(repeats)}};
    PX_ASSIGN_OR_RETURN(stream_, LibavStreamWriter::Open(path(), width(), height(), spec));
    return OkStatus();
  }

 protected:
  Status WriteFrame(const cv::Mat& bgr, int index) override {
    if (palette_.colours().empty() ||
        palette_.MeanSquaredError(bgr, kSampleStep) > std::max(kRebuildMinError, kRebuildErrorRatio * built_error_)) {
      palette_ = MedianCutPalette::Build(bgr, kColours, kSampleStep);
      built_error_ = palette_.MeanSquaredError(bgr, kSampleStep);
      ++palettes_built_;
    }
    PX_ASSIGN_OR_RETURN(AVFrame * frame, stream_->WritableFrame());
    uint32_t* argb = reinterpret_cast<uint32_t*>(frame->data[1]);
    for (int i = 0; i < 256; ++i) argb[i] = 0xff000000u;  // unused entries: opaque black
    for (size_t i = 0; i < palette_.colours().size(); ++i) {
      const cv::Vec3b& c = palette_.colours()[i];
      argb[i] = 0xff000000u | (uint32_t{c[2]} << 16) | (uint32_t{c[1]} << 8) | c[0];
    }
    argb[kTransparentIndex] = 0x00000000u;
    cv::Mat indices(height(), width(), CV_8U, frame->data[0], static_cast<size_t>(frame->linesize[0]));
    palette_.Map(bgr, dither_, &indices);
    // Frame i is shown at i / fps seconds, rounded to the 1/100 s GIF can store; the delays
    // alternate (3, 3, 4 cs at 30 fps) so the clip keeps its length.
    return stream_->WriteFrame(std::llround(index * 100.0 / fps_));
  }

  Status FinishClip() override { return stream_->Finish(); }

 private:
  double fps_;
  bool dither_;
  std::unique_ptr<LibavStreamWriter> stream_;
  MedianCutPalette palette_;
  double built_error_ = 0;
  int palettes_built_ = 0;
};

}  // namespace

StatusOr<std::unique_ptr<ClipWriter>> OpenGifWriter(const std::filesystem::path& path,
                                                    int width,
                                                    int height,
                                                    const ClipOptions& options) {
  PX_RETURN_IF_ERROR(CheckClipSize(path, width, height, 1, 65535));
  auto writer = std::make_unique<GifWriter>(path, width, height, options);
  PX_RETURN_IF_ERROR(writer->Init(options));
  return std::unique_ptr<ClipWriter>(std::move(writer));
}

}  // namespace px::clip
