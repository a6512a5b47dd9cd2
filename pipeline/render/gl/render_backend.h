// Which render back end draws the frames: the CPU or GL (EGL or OSMesa), chosen automatically or
// forced (`--gl=cpu|egl|osmesa`, daemon `render.backend`). The rule for "auto", from measurement
// (README.md in this folder): GL when the context is hardware (an EGL GPU device), the CPU
// otherwise, because on a CPU-only machine Mesa's llvmpipe renders the segment passes several
// times slower than the CPU renderer (2 cores: ~2.5 vs ~14 fps at 480x320 under load). A forced
// GL back end that cannot start falls back to the CPU with the reason logged and returned.
#pragma once

#include <memory>
#include <string>
#include <string_view>

#include "pipeline/core/status.h"
#include "pipeline/render/gl/gl_context.h"

namespace px::render::gl {

enum class RenderBackend { kAuto, kCpu, kEgl, kOsmesa };

std::string_view RenderBackendName(RenderBackend backend);  // "auto", "cpu", "egl", "osmesa"
StatusOr<RenderBackend> ParseRenderBackend(std::string_view name);

struct BackendChoice {
  RenderBackend backend = RenderBackend::kCpu;  // kCpu, kEgl or kOsmesa: what was chosen
  std::unique_ptr<GlContext> context;           // the context to render with, when GL was chosen
  std::string reason;                           // one line for the log and the report
};

// Decides and, for GL, creates the context. Never fails: the CPU is always there; `reason` says
// why GL was not used (the platform's own error, or "software only"). `base` supplies the
// library names and GL version; its platform is set from `requested`.
BackendChoice ChooseRenderBackend(RenderBackend requested, const GlContextOptions& base = {});

}  // namespace px::render::gl
