#include "tests/testing/animation_probe.h"

#include <webp/demux.h>

#include <cstring>
#include <fstream>
#include <iterator>
#include <opencv2/imgproc.hpp>

#include "tests/testing/video_probe.h"

namespace px::testing {
namespace {

StatusOr<std::string> ReadAll(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return NotFoundError(path.string() + ": cannot open");
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// GIF: the NETSCAPE2.0 application block holds the repeat count (0 = forever); without the
// block a GIF plays once.
int GifPlays(const std::string& bytes) {
  const size_t at = bytes.find("NETSCAPE2.0");
  if (at == std::string::npos || at + 11 + 5 > bytes.size()) return 1;
  const unsigned char* block = reinterpret_cast<const unsigned char*>(bytes.data() + at + 11);
  if (block[0] != 3 || block[1] != 1) return 1;
  const int repeats = block[2] | (block[3] << 8);
  return repeats == 0 ? 0 : repeats + 1;
}

StatusOr<AnimationProbe> ProbeWebp(const std::filesystem::path& path, const std::string& bytes) {
  WebPData data = {reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()};
  WebPAnimDecoderOptions options;
  if (!WebPAnimDecoderOptionsInit(&options)) return InternalError("libwebpdemux version mismatch");
  options.color_mode = MODE_BGRA;
  WebPAnimDecoder* decoder = WebPAnimDecoderNew(&data, &options);
  if (decoder == nullptr) return DataLossError(path.string() + ": not an animated WebP libwebp can decode");
  WebPAnimInfo info;
  WebPAnimDecoderGetInfo(decoder, &info);
  AnimationProbe probe;
  probe.format = "webp";
  probe.width = static_cast<int>(info.canvas_width);
  probe.height = static_cast<int>(info.canvas_height);
  probe.plays = static_cast<int>(info.loop_count);
  while (WebPAnimDecoderHasMoreFrames(decoder)) {
    uint8_t* canvas = nullptr;
    int end_ms = 0;
    if (!WebPAnimDecoderGetNext(decoder, &canvas, &end_ms)) break;
    cv::Mat bgra(probe.height, probe.width, CV_8UC4, canvas);
    cv::cvtColor(bgra, probe.last_frame, cv::COLOR_BGRA2BGR);
    if (probe.frames == 0) probe.first_frame = probe.last_frame.clone();
    ++probe.frames;
    probe.duration_s = end_ms / 1000.0;
  }
  WebPAnimDecoderDelete(decoder);
  return probe;
}

}  // namespace

StatusOr<AnimationProbe> ProbeAnimation(const std::filesystem::path& path) {
  PX_ASSIGN_OR_RETURN(std::string bytes, ReadAll(path));
  if (bytes.size() >= 12 && bytes.compare(0, 4, "RIFF") == 0 && bytes.compare(8, 4, "WEBP") == 0) {
    return ProbeWebp(path, bytes);
  }
  if (bytes.compare(0, 6, "GIF89a") != 0 && bytes.compare(0, 6, "GIF87a") != 0) {
    return DataLossError(path.string() + ": neither a GIF nor a WebP");
  }
  PX_ASSIGN_OR_RETURN(VideoProbe video, ProbeVideo(path));
  AnimationProbe probe;
  probe.format = "gif";
  probe.width = video.width;
  probe.height = video.height;
  probe.frames = video.frames_decoded;
  probe.plays = GifPlays(bytes);
  probe.duration_s = video.duration_s;
  probe.first_frame = video.first_frame;
  probe.last_frame = video.last_frame;
  return probe;
}

}  // namespace px::testing
