// Write and read times of one full-size lattice frame (4056x3040, a 12 MP sensor) per stored
// format: PNG (BGR888) and raw (SRGGB8, NV12). Figures only; nothing is asserted.
#include <benchmark/benchmark.h>
#include <stdlib.h>

#include <filesystem>
#include <opencv2/core.hpp>
#include <string>

#include "capture/recording.h"

namespace px {
namespace {

namespace fs = std::filesystem;

constexpr int kWidth = 4056;
constexpr int kHeight = 3040;

// Smooth gradients plus mild noise: compresses roughly like a real photograph.
Recording FullSizeRecording(PixelFormat format) {
  cv::Mat bgr(kHeight, kWidth, CV_8UC3);
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      bgr.at<cv::Vec3b>(y, x) = cv::Vec3b(x * 255 / kWidth, y * 255 / kHeight, (x + y) * 255 / (kWidth + kHeight));
    }
  }
  cv::Mat noise(kHeight, kWidth, CV_8UC3);
  cv::RNG(7).fill(noise, cv::RNG::UNIFORM, 0, 8);
  bgr += noise;
  Recording recording;
  recording.source.model = "bench";
  recording.created_by = "recording_benchmark";
  Frame frame;
  frame.image = FromBgr(bgr, format).value();
  recording.frames.frames.push_back(std::move(frame));
  return recording;
}

fs::path ScratchFolder() {
  std::string pattern = (fs::temp_directory_path() / "px_replay_bench_XXXXXX").string();
  return ::mkdtemp(pattern.data());
}

void BM_WriteRecording(benchmark::State& state) {
  const auto format = static_cast<PixelFormat>(state.range(0));
  const Recording recording = FullSizeRecording(format);
  const fs::path root = ScratchFolder();
  int i = 0;
  for (auto _ : state) {
    const fs::path dir = root / std::to_string(i++);
    if (!WriteRecording(dir, recording).ok()) state.SkipWithError("write failed");
    state.PauseTiming();
    fs::remove_all(dir);
    state.ResumeTiming();
  }
  fs::remove_all(root);
  state.SetLabel(std::string(PixelFormatName(format)));
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(recording.frames.frames[0].image.bytes.size()));
}

void BM_ReadRecording(benchmark::State& state) {
  const auto format = static_cast<PixelFormat>(state.range(0));
  const fs::path root = ScratchFolder();
  const Recording recording = FullSizeRecording(format);
  if (!WriteRecording(root / "shot", recording).ok()) state.SkipWithError("write failed");
  for (auto _ : state) {
    StatusOr<Recording> read = ReadRecording(root / "shot");
    if (!read.ok()) state.SkipWithError("read failed");
    benchmark::DoNotOptimize(read);
  }
  fs::remove_all(root);
  state.SetLabel(std::string(PixelFormatName(format)));
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(recording.frames.frames[0].image.bytes.size()));
}

void Formats(benchmark::internal::Benchmark* b) {
  for (PixelFormat f : {PixelFormat::kBgr888, PixelFormat::kBayerRggb8, PixelFormat::kNv12}) {
    b->Arg(static_cast<int>(f));
  }
  b->Unit(benchmark::kMillisecond)->UseRealTime();
}

BENCHMARK(BM_WriteRecording)->Apply(Formats);
BENCHMARK(BM_ReadRecording)->Apply(Formats);

}  // namespace
}  // namespace px
