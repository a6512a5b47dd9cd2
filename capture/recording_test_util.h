// Shared helpers for the capture tests: a scratch folder per test, generated test images
// (gradients plus seeded noise, through px::FromBgr) and small recordings built from them.
#pragma once

#include <cstdint>
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "capture/recording.h"
#include "tests/testing/temp_dir.h"

namespace px::capture::testing {

using ScratchDir = px::testing::TempDir;

// Horizontal, vertical and diagonal gradients in B, G, R plus uniform noise of +-20 from `seed`.
cv::Mat GradientNoiseBgr(int width, int height, uint64_t seed);
// The same picture as a sensor of `format` would deliver it.
RawImage TestImage(PixelFormat format, int width, int height, uint64_t seed);

// A 3x3 lattice of 40x30 tiles with 4 px gaps: a 136x106 sensor (even, so every format fits).
RigCalibration SmallPop9Rig();
// One lattice frame of `format` with SmallPop9Rig, fixed metadata (capture 41, sequence 1000+seed).
Recording LatticeRecording(PixelFormat format, uint64_t seed = 1);
// `num_frames` images of 64x48 in `format`, each with its own lens in the rig, sequences 10, 11, ...
Recording ImageSetRecording(int num_frames, PixelFormat format, uint64_t seed = 1);

// Fails the current test (with the frame index) where the two differ in any field or byte.
void ExpectSameRecording(const Recording& expected, const Recording& actual);

// `bgr` as a JPEG of quality 95.
std::vector<uint8_t> Jpeg(const cv::Mat& bgr);
// An MPO file of `images` (JPEGs) as a 3D camera writes it: the first JPEG with an APP2 MP index
// (big-endian TIFF: version, number of images, MP entries) right after its SOI, the others after it.
std::vector<uint8_t> MakeMpo(const std::vector<std::vector<uint8_t>>& images);
// Writes `bytes` to `path` and returns the path.
std::filesystem::path WriteBytes(const std::filesystem::path& path, const std::vector<uint8_t>& bytes);

std::string ReadText(const std::filesystem::path& path);
void WriteText(const std::filesystem::path& path, const std::string& text);

}  // namespace px::capture::testing
