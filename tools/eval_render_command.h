// `parallax eval render`: PSNR, SSIM and hole ratio of novel views (eval/render/render_eval.h).
#pragma once

#include <CLI/CLI.hpp>

namespace px::cli {

void AddEvalRenderCommand(CLI::App& eval);

}  // namespace px::cli
