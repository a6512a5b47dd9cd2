// `parallax eval depth`: depth against ground truth on every set found (eval/depth/depth_eval.h),
// ours beside the first plane sweep and OpenCV's StereoSGBM, as a table or JSON.
#pragma once

#include <CLI/CLI.hpp>

namespace px::cli {

void AddEvalDepthCommand(CLI::App& eval);

}  // namespace px::cli
