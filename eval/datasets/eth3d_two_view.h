// ETH3D two-view stereo scenes in the layout of ../shared/data/eth3d_two_view (SOURCES.md 5):
// im0.png (left), im1.png (right), disp0.pfm (left GT; inf/NaN = unknown) and calib.txt
// (Middlebury style: cam0=[fx 0 cx; 0 fy cy; 0 0 1], cam1, doffs, baseline in mm, ndisp).
#pragma once

#include <filesystem>

#include "eval/datasets/stereo_pair.h"
#include "pipeline/core/status.h"

namespace px::eval {

// True when `dir` holds im0.png, im1.png, disp0.pfm and calib.txt.
bool IsEth3dPairDir(const std::filesystem::path& dir);

// Loads the pair in `dir` with its calibration; name = "eth3d/<folder>". Unknown GT becomes NaN.
// The search range is [0.5, min(ndisp, 64)] px: ETH3D writes the image width as ndisp, and its
// low-resolution two-view scenes stay below 64 px. A non-zero doffs (principal points that
// differ) is refused: the pair would not be a plain rectified pair. Errors name the file and key.
StatusOr<StereoPair> LoadEth3dPair(const std::filesystem::path& dir);

}  // namespace px::eval
