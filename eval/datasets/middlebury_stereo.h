// Middlebury two-view stereo pairs in the layouts of ../shared/data (SOURCES.md 3 and 4):
//   2003 quarter size: im2.png (left), im6.png (right), disp2.png (left GT, d = value / 4)
//   2006 third size:   view1.png (left), view5.png (right), disp1.png (left GT, d = value / 3)
// A GT value of 0 means unknown. No calibration ships with these sizes: the focal length is
// taken as the image width and the baseline as 0.1 m, which only scales depth; disparities, the
// measure that is compared, are exact.
#pragma once

#include <filesystem>

#include "eval/datasets/stereo_pair.h"
#include "pipeline/core/status.h"

namespace px::eval {

// True when `dir` holds one of the two layouts above.
bool IsMiddleburyPairDir(const std::filesystem::path& dir);

// Loads the pair in `dir`; name = "<parent folder>/<folder>". The search range is
// [0.5, 255 / scale] px: what the 8-bit maps can encode (63.75 for 2003, 85 for 2006). Errors
// name the file and what is wrong.
StatusOr<StereoPair> LoadMiddleburyPair(const std::filesystem::path& dir);

}  // namespace px::eval
