// Time to encode a standard clip: 150 frames of 640x480 (5 s at 30 fps), with the default
// options (CRF 20, veryfast). The content is a detailed texture panning 1 px a frame, as a
// dolly's background does. Prints figures, asserts nothing.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "pipeline/clip/mp4_writer.h"

namespace px::clip {
namespace {

void BM_Encode150Frames(benchmark::State& state) {
  cv::setNumThreads(0);
  cv::RNG rng(7);
  cv::Mat texture(480, 640 + 150, CV_8UC3);
  rng.fill(texture, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(texture, texture, cv::Size(0, 0), 1.5);  // camera-like detail, not pure noise
  std::vector<cv::Mat> frames;
  for (int i = 0; i < 150; ++i) frames.push_back(texture(cv::Rect(i, 0, 640, 480)).clone());
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("px_encode_benchmark_" + std::to_string(::getpid()) + ".mp4");
  Mp4Options options;
  options.preset = state.range(0) == 0 ? "ultrafast" : state.range(0) == 1 ? "veryfast" : "medium";
  for (auto _ : state) {
    auto writer = Mp4Writer::Open(path, 640, 480, options);
    if (!writer.ok()) {
      state.SkipWithError(writer.status().ToString().c_str());
      break;
    }
    for (const cv::Mat& frame : frames) (void)(*writer)->Write(frame);
    (void)(*writer)->Finish();
  }
  state.SetLabel(options.preset);
  state.counters["bytes"] = static_cast<double>(std::filesystem::file_size(path));
  std::filesystem::remove(path);
}
BENCHMARK(BM_Encode150Frames)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace px::clip
