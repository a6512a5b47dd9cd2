// The scene renderer the product uses: the back end chosen by `render_backend.h` (`--gl`,
// `render.backend`), with the CPU reference (CpuSceneRenderer) behind it. What GL cannot do is
// rendered by the CPU and said so: the whole scene when GL cannot start (library missing, no
// GPU for `auto`), offline quality (paper 6.2 is CPU only) or a scene GL refuses, and a
// single frame when GL fails on it (the frame is drawn by the CPU, the first reason kept).
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "pipeline/core/layered_depth.h"
#include "pipeline/core/view.h"
#include "pipeline/render/gl/render_backend.h"
#include "pipeline/render/render_options.h"
#include "pipeline/render/scene_renderer.h"

namespace px::render::gl {

struct RenderBackendOptions {
  RenderBackend backend = RenderBackend::kAuto;
  // Library names and GL version (its platform is set from `backend`); tests change the names.
  GlContextOptions context;
  Status Validate() const;
};

class BackendSceneRenderer final : public SceneRenderer {
 public:
  // Errors only where the CPU reference fails too (CpuSceneRenderer::Create: no views, images of
  // the wrong size); everything GL lacks is a fallback with its reason.
  static StatusOr<std::unique_ptr<BackendSceneRenderer>> Create(const std::vector<View>& views,
                                                                const std::vector<LayeredDepthView>& layers,
                                                                const RenderOptions& render,
                                                                const RenderBackendOptions& backend);

  // The back end drawing the frames: "cpu", "gl-osmesa" or "gl-egl".
  std::string_view BackendName() const override { return primary_->BackendName(); }
  // Why that back end, one line ("gl-osmesa: asked for, osmesa: llvmpipe ...", "cpu: GL failed (...)").
  const std::string& reason() const { return reason_; }
  // The scene's warnings (bad segments, texels, views), from whichever back end prepared it.
  const std::vector<std::string>& warnings() const { return warnings_; }
  // Frames the CPU drew because GL failed on them, and the first such failure.
  int cpu_fallback_frames() const { return cpu_fallback_frames_; }
  const std::string& cpu_fallback_reason() const { return cpu_fallback_reason_; }

  StatusOr<FrameRender> Render(const VirtualCamera& camera) override;
  StatusOr<CoverageReport> Coverage(const CameraModel& camera, const Rigid3& cam_from_world) override;

 private:
  BackendSceneRenderer() = default;
  StatusOr<SceneRenderer*> Cpu();  // the CPU reference, made on first use when GL is primary

  std::vector<View> views_;  // kept for a late CPU fallback (shallow copies)
  std::vector<LayeredDepthView> layers_;
  RenderOptions render_;
  std::unique_ptr<SceneRenderer> primary_;
  std::unique_ptr<SceneRenderer> cpu_;  // set when the CPU is primary's fallback
  std::string reason_;
  std::vector<std::string> warnings_;
  int cpu_fallback_frames_ = 0;
  std::string cpu_fallback_reason_;
};

}  // namespace px::render::gl
