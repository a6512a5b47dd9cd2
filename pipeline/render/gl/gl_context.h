// A headless GL context, with no display and no window system: EGL on a GPU device when one
// exists (found by enumerating EGL devices and skipping Mesa's software device), else EGL on
// Mesa's surfaceless platform, else OSMesa (Mesa's llvmpipe into client memory). Rendering goes
// to framebuffer objects; the context's own surface is never drawn to. Each context carries the
// GL entry points resolved through its own platform (gl_functions.h), and both platforms run the
// same GLSL 3.30 core shaders.
//
// The GL libraries are opened with dlopen at run time, so a machine without libEGL or libOSMesa
// still runs (the pipeline then falls back to the CPU back end, naming the missing library).
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "pipeline/core/status.h"
#include "pipeline/render/gl/gl_functions.h"

namespace px::render::gl {

enum class GlPlatform {
  kAuto,    // EGL (GPU device, else surfaceless), else OSMesa
  kEgl,     // EGL only: a GPU device, else Mesa's surfaceless platform
  kOsmesa,  // OSMesa only
};

std::string_view GlPlatformName(GlPlatform platform);  // "auto", "egl", "osmesa"
StatusOr<GlPlatform> ParseGlPlatform(std::string_view name);

struct GlContextOptions {
  GlPlatform platform = GlPlatform::kAuto;
  // The GL core profile version to ask for, [3.3, 4.6]; drivers give this or newer. The shaders
  // need 3.3.
  int gl_major = 3;
  int gl_minor = 3;
  // With false, a software rasteriser (llvmpipe, softpipe, swrast) is refused: for callers that
  // only want GL when it is hardware.
  bool allow_software = true;
  // The shared objects to open (sonames). Changed only by tests of a machine without them.
  std::string egl_library = "libEGL.so.1";
  std::string osmesa_library = "libOSMesa.so.8";

  Status Validate() const;
};

// What was created, for logs and reports.
struct GlContextInfo {
  std::string platform;   // "egl-device", "egl-surfaceless" or "osmesa"
  std::string vendor;     // GL_VENDOR
  std::string renderer;   // GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
  std::string version;    // GL_VERSION, e.g. "4.5 (Core Profile) Mesa 22.3.6"
  bool software = false;  // a CPU rasteriser (llvmpipe, softpipe, swrast)
  int max_texture_size = 0;
  int max_array_texture_layers = 0;
  int max_draw_buffers = 0;

  std::string ToString() const;  // "osmesa: llvmpipe (...), 4.5 (Core Profile) Mesa 22.3.6"
};

class GlContext {
 public:
  virtual ~GlContext() = default;
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  // Binds the context to the calling thread (a context is current on one thread at a time;
  // callers serialise). Errors name the platform.
  virtual Status MakeCurrent() = 0;
  // Unbinds it from the calling thread, so another thread may take it.
  virtual void ReleaseCurrent() = 0;

  const GlFunctions& gl() const { return gl_; }
  const GlContextInfo& info() const { return info_; }
  // "gl-egl" or "gl-osmesa" (the SceneRenderer back-end name).
  std::string_view BackendName() const;

 protected:
  GlContext() = default;
  // Resolves the GL entry points and fills info_; the context must be current. Refuses software
  // rasterisers when `allow_software` is false.
  Status LoadFunctionsAndInfo(const GlProcResolver& resolve, std::string platform, bool allow_software);

 private:
  GlFunctions gl_;
  GlContextInfo info_;
};

// Creates a context on the platform asked for. With kAuto every platform is tried in order and
// the error, when all fail, names each one's reason ("egl: ...; osmesa: ...").
StatusOr<std::unique_ptr<GlContext>> CreateGlContext(const GlContextOptions& options = {});

// The platform-specific halves (egl_context.cc, osmesa_context.cc).
StatusOr<std::unique_ptr<GlContext>> CreateEglContext(const GlContextOptions& options);
StatusOr<std::unique_ptr<GlContext>> CreateOsmesaContext(const GlContextOptions& options);

// Makes a context current for a scope and releases it at the end.
class ScopedCurrent {
 public:
  explicit ScopedCurrent(GlContext* context) : context_(context) { status_ = context_->MakeCurrent(); }
  ~ScopedCurrent() {
    if (status_.ok()) context_->ReleaseCurrent();
  }
  ScopedCurrent(const ScopedCurrent&) = delete;
  ScopedCurrent& operator=(const ScopedCurrent&) = delete;
  const Status& status() const { return status_; }

 private:
  GlContext* context_;
  Status status_;
};

}  // namespace px::render::gl
