#include "pipeline/render/gl/backend_scene_renderer.h"

#include <utility>

#include "pipeline/core/log.h"
#include "pipeline/render/cpu_scene_renderer.h"
#include "pipeline/render/gl/gl_scene_renderer.h"

namespace px::render::gl {

Status RenderBackendOptions::Validate() const {
  GlContextOptions checked = context;
  checked.platform = GlPlatform::kAuto;  // set from `backend` when used
  return checked.Validate().WithContext("render.backend");
}

StatusOr<std::unique_ptr<BackendSceneRenderer>> BackendSceneRenderer::Create(
    const std::vector<View>& views,
    const std::vector<LayeredDepthView>& layers,
    const RenderOptions& render,
    const RenderBackendOptions& backend) {
  PX_RETURN_IF_ERROR(render.Validate());
  PX_RETURN_IF_ERROR(backend.Validate());
  if (views.size() != layers.size()) {
    return InvalidArgumentError("render: " + std::to_string(views.size()) + " views but " +
                                std::to_string(layers.size()) + " layered depth views");
  }
  auto log = Logger("render");
  std::unique_ptr<BackendSceneRenderer> out(new BackendSceneRenderer());
  out->views_ = views;
  out->layers_ = layers;
  out->render_ = render;
  std::string gl_refused;  // why GL is not primary, when it was possible
  if (backend.backend != RenderBackend::kCpu && render.quality == RenderQuality::kOffline) {
    gl_refused = "cpu: offline quality (paper 6.2) is rendered on the CPU only";
    log->info("render back end: {}", gl_refused);
  } else if (backend.backend != RenderBackend::kCpu) {
    BackendChoice choice = ChooseRenderBackend(backend.backend, backend.context);
    if (choice.context == nullptr) {
      gl_refused = choice.reason;  // ChooseRenderBackend logged it
    } else {
      std::vector<PosedLayeredView> posed;
      posed.reserve(views.size());
      for (size_t v = 0; v < views.size(); ++v) posed.push_back({layers[v], views[v].cam_from_world});
      const GlSceneRendererOptions gl_options = GlOptionsFrom(render);
      StatusOr<std::unique_ptr<GlSceneRenderer>> gl =
          GlSceneRenderer::Create(std::move(posed), std::move(choice.context), gl_options);
      if (gl.ok()) {
        out->reason_ = choice.reason;
        out->warnings_ = (*gl)->warnings();
        out->primary_ = std::move(gl).value();
      } else {
        gl_refused = "cpu: the GL renderer cannot draw this scene (" + gl.status().message() + ")";
        log->warn("render back end: {}", gl_refused);
      }
    }
  } else {
    out->reason_ = "cpu: asked for";
    log->info("render back end: {}", out->reason_);
  }
  if (out->primary_ == nullptr) {
    PX_ASSIGN_OR_RETURN(std::unique_ptr<CpuSceneRenderer> cpu, CpuSceneRenderer::Create(views, layers, render));
    out->warnings_ = cpu->warnings();
    out->primary_ = std::move(cpu);
    if (!gl_refused.empty()) out->reason_ = gl_refused;
    // Asked for GL by name and not given it: a degraded result the clip's warnings name too.
    if (!gl_refused.empty() && backend.backend != RenderBackend::kAuto) {
      out->warnings_.push_back("asked for " + std::string(RenderBackendName(backend.backend)) + ", drawn by the " +
                               gl_refused);
    }
  }
  return out;
}

StatusOr<SceneRenderer*> BackendSceneRenderer::Cpu() {
  if (cpu_ == nullptr) {
    PX_ASSIGN_OR_RETURN(std::unique_ptr<CpuSceneRenderer> cpu, CpuSceneRenderer::Create(views_, layers_, render_));
    cpu_ = std::move(cpu);
  }
  return cpu_.get();
}

StatusOr<FrameRender> BackendSceneRenderer::Render(const VirtualCamera& camera) {
  StatusOr<FrameRender> frame = primary_->Render(camera);
  if (frame.ok() || primary_->BackendName() == "cpu") return frame;
  // GL failed on this frame: the CPU reference draws it; its error wins when it fails too.
  PX_ASSIGN_OR_RETURN(SceneRenderer * cpu, Cpu());
  StatusOr<FrameRender> cpu_frame = cpu->Render(camera);
  if (!cpu_frame.ok()) return cpu_frame.status();
  if (cpu_fallback_frames_++ == 0) {
    cpu_fallback_reason_ = frame.status().message();
    Logger("render")->warn(
        "render: {} failed on a frame, drawn on the cpu instead: {}", primary_->BackendName(), cpu_fallback_reason_);
  }
  return cpu_frame;
}

StatusOr<CoverageReport> BackendSceneRenderer::Coverage(const CameraModel& camera, const Rigid3& cam_from_world) {
  StatusOr<CoverageReport> report = primary_->Coverage(camera, cam_from_world);
  if (report.ok() || primary_->BackendName() == "cpu") return report;
  PX_ASSIGN_OR_RETURN(SceneRenderer * cpu, Cpu());
  return cpu->Coverage(camera, cam_from_world);
}

}  // namespace px::render::gl
