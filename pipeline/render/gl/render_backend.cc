#include "pipeline/render/gl/render_backend.h"

#include "pipeline/core/log.h"

namespace px::render::gl {

std::string_view RenderBackendName(RenderBackend backend) {
  switch (backend) {
    case RenderBackend::kAuto:
      return "auto";
    case RenderBackend::kCpu:
      return "cpu";
    case RenderBackend::kEgl:
      return "egl";
    case RenderBackend::kOsmesa:
      return "osmesa";
  }
  return "?";
}

StatusOr<RenderBackend> ParseRenderBackend(std::string_view name) {
  for (RenderBackend b : {RenderBackend::kAuto, RenderBackend::kCpu, RenderBackend::kEgl, RenderBackend::kOsmesa}) {
    if (name == RenderBackendName(b)) return b;
  }
  return InvalidArgumentError("render backend: \"" + std::string(name) + "\" is not one of auto, cpu, egl, osmesa");
}

BackendChoice ChooseRenderBackend(RenderBackend requested, const GlContextOptions& base) {
  BackendChoice choice;
  auto log = Logger("render");
  if (requested == RenderBackend::kCpu) {
    choice.reason = "cpu: asked for";
    log->info("render back end: {}", choice.reason);
    return choice;
  }
  GlContextOptions options = base;
  options.platform = requested == RenderBackend::kOsmesa ? GlPlatform::kOsmesa : GlPlatform::kEgl;
  // auto: only hardware GL beats the CPU renderer (README.md), so only an EGL GPU device counts.
  options.allow_software = requested != RenderBackend::kAuto;
  StatusOr<std::unique_ptr<GlContext>> context = CreateGlContext(options);
  if (!context.ok()) {
    choice.reason = "cpu: " + std::string(requested == RenderBackend::kAuto ? "no hardware GL" : "GL failed") + " (" +
                    context.status().message() + ")";
    (requested == RenderBackend::kAuto ? log->info("render back end: {}", choice.reason)
                                       : log->warn("render back end: {}", choice.reason));
    return choice;
  }
  choice.backend = requested == RenderBackend::kOsmesa ? RenderBackend::kOsmesa : RenderBackend::kEgl;
  choice.reason = std::string((*context)->BackendName()) + ": " +
                  (requested == RenderBackend::kAuto ? "hardware GL found, " : "asked for, ") +
                  (*context)->info().ToString();
  choice.context = std::move(context).value();
  log->info("render back end: {}", choice.reason);
  return choice;
}

}  // namespace px::render::gl
