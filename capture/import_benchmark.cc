// Import times of a user's files at a real camera's resolution (capture/import_images.h): one
// 24 MP photo of a 3x3 lattice of views (6000x4000, dark gaps between the tiles) and MPO files of
// two 12 MP and of two 24 MP images. "read" is what `parallax clip FILE` does before processing
// (decoding, EXIF, the frames of a recording in memory); "read+write" adds storing the recording
// as `parallax import` does. Figures only; nothing is asserted.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "capture/import_images.h"
#include "capture/recording.h"
#include "capture/recording_test_util.h"

namespace px {
namespace {

namespace fs = std::filesystem;
using capture::testing::GradientNoiseBgr;
using capture::testing::Jpeg;
using capture::testing::MakeMpo;
using capture::testing::ScratchDir;
using capture::testing::WriteBytes;

// Smooth detail with mild noise, so the JPEG is about the size a camera's would be (noise alone
// compresses far worse than a photograph, a flat image far better).
cv::Mat PhotoLike(int width, int height, uint64_t seed) {
  cv::Mat small = GradientNoiseBgr(width / 8, height / 8, seed), photo, noise(height, width, CV_8UC3);
  cv::resize(small, photo, cv::Size(width, height), 0, 0, cv::INTER_CUBIC);
  cv::RNG(seed).fill(noise, cv::RNG::UNIFORM, 0, 20);
  return photo + noise;
}

// A 3x3 lattice of views on a 6000x4000 frame: tiles with 80 px dark borders between them.
cv::Mat LatticeFrame() {
  constexpr int kWidth = 6000, kHeight = 4000, kGap = 80;
  cv::Mat frame = PhotoLike(kWidth, kHeight, 1);
  for (int i = 0; i <= 3; ++i) {
    const int x = i * (kWidth - kGap) / 3, y = i * (kHeight - kGap) / 3;
    frame(cv::Rect(x, 0, kGap, kHeight)).setTo(cv::Scalar::all(8));
    frame(cv::Rect(0, y, kWidth, kGap)).setTo(cv::Scalar::all(8));
  }
  return frame;
}

enum class File { kLatticePhoto24Mp, kMpo2x12Mp, kMpo2x24Mp };

fs::path MakeFile(File file, const fs::path& folder) {
  switch (file) {
    case File::kLatticePhoto24Mp:
      return WriteBytes(folder / "lattice.jpg", Jpeg(LatticeFrame()));
    case File::kMpo2x12Mp:
      return WriteBytes(folder / "pair12.mpo",
                        MakeMpo({Jpeg(PhotoLike(4000, 3000, 2)), Jpeg(PhotoLike(4000, 3000, 3))}));
    case File::kMpo2x24Mp:
      return WriteBytes(folder / "pair24.mpo",
                        MakeMpo({Jpeg(PhotoLike(6000, 4000, 4)), Jpeg(PhotoLike(6000, 4000, 5))}));
  }
  return {};
}

const char* FileLabel(File file) {
  switch (file) {
    case File::kLatticePhoto24Mp:
      return "lattice photo 6000x4000 (24 MP), 3x3";
    case File::kMpo2x12Mp:
      return "MPO, 2 images of 4000x3000 (24 MP in all)";
    case File::kMpo2x24Mp:
      return "MPO, 2 images of 6000x4000 (48 MP in all)";
  }
  return "";
}

void BM_Import(benchmark::State& state) {
  const auto file = static_cast<File>(state.range(0));
  const bool write = state.range(1) != 0;
  const ScratchDir scratch;  // removed with everything in it when the benchmark ends
  const fs::path& root = scratch.path();
  const fs::path path = MakeFile(file, root);
  std::error_code error;
  const uintmax_t file_bytes = fs::file_size(path, error);
  if (error) {
    state.SkipWithError(("cannot write " + path.string()).c_str());
    return;
  }
  int i = 0;
  for (auto _ : state) {
    std::vector<std::string> warnings;
    StatusOr<Recording> recording = file == File::kLatticePhoto24Mp
                                        ? RecordingFromLatticePhoto(path, LatticeHint{}, &warnings)
                                        : RecordingFromImages({path}, &warnings);
    if (!recording.ok()) {
      state.SkipWithError(recording.status().ToString().c_str());
      break;
    }
    if (write && !WriteRecording(root / std::to_string(i++), *recording).ok()) state.SkipWithError("write failed");
    benchmark::DoNotOptimize(recording);
  }
  state.counters["file_mb"] = static_cast<double>(file_bytes) / (1 << 20);  // MiB
  state.SetLabel(std::string(FileLabel(file)) + (write ? ", read+write" : ", read"));
}

void Files(benchmark::internal::Benchmark* b) {
  for (File f : {File::kLatticePhoto24Mp, File::kMpo2x12Mp, File::kMpo2x24Mp}) {
    for (int write : {0, 1}) b->Args({static_cast<int>(f), write});
  }
  b->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);
}

BENCHMARK(BM_Import)->Apply(Files);

}  // namespace
}  // namespace px
