// EGL without a display: a GPU found by enumerating EGL devices (EGL_EXT_device_enumeration),
// skipping Mesa's software device, else Mesa's surfaceless platform (llvmpipe where there is no
// GPU). The context is made current without a surface (EGL_KHR_surfaceless_context); rendering
// goes to framebuffer objects. libEGL is opened with dlopen.
#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <array>
#include <cstdio>
#include <memory>
#include <string>

#include "pipeline/render/gl/gl_context.h"
#include "pipeline/render/gl/shared_library.h"

namespace px::render::gl {
namespace {

struct EglLibrary {
  PFNEGLGETPROCADDRESSPROC get_proc_address = nullptr;
  PFNEGLQUERYSTRINGPROC query_string = nullptr;
  PFNEGLINITIALIZEPROC initialize = nullptr;
  PFNEGLBINDAPIPROC bind_api = nullptr;
  PFNEGLCREATECONTEXTPROC create_context = nullptr;
  PFNEGLDESTROYCONTEXTPROC destroy_context = nullptr;
  PFNEGLMAKECURRENTPROC make_current = nullptr;
  PFNEGLGETERRORPROC get_error = nullptr;
  // Extensions (resolved through eglGetProcAddress; nullptr when absent).
  PFNEGLGETPLATFORMDISPLAYEXTPROC get_platform_display = nullptr;
  PFNEGLQUERYDEVICESEXTPROC query_devices = nullptr;
  PFNEGLQUERYDEVICESTRINGEXTPROC query_device_string = nullptr;
};

StatusOr<EglLibrary> LoadEgl(const std::string& soname) {
  PX_ASSIGN_OR_RETURN(void* handle, OpenSharedLibrary(soname, "egl", "libegl1"));
  EglLibrary egl;
  egl.get_proc_address = reinterpret_cast<PFNEGLGETPROCADDRESSPROC>(LibrarySymbol(handle, "eglGetProcAddress"));
  egl.query_string = reinterpret_cast<PFNEGLQUERYSTRINGPROC>(LibrarySymbol(handle, "eglQueryString"));
  egl.initialize = reinterpret_cast<PFNEGLINITIALIZEPROC>(LibrarySymbol(handle, "eglInitialize"));
  egl.bind_api = reinterpret_cast<PFNEGLBINDAPIPROC>(LibrarySymbol(handle, "eglBindAPI"));
  egl.create_context = reinterpret_cast<PFNEGLCREATECONTEXTPROC>(LibrarySymbol(handle, "eglCreateContext"));
  egl.destroy_context = reinterpret_cast<PFNEGLDESTROYCONTEXTPROC>(LibrarySymbol(handle, "eglDestroyContext"));
  egl.make_current = reinterpret_cast<PFNEGLMAKECURRENTPROC>(LibrarySymbol(handle, "eglMakeCurrent"));
  egl.get_error = reinterpret_cast<PFNEGLGETERRORPROC>(LibrarySymbol(handle, "eglGetError"));
  if (egl.get_proc_address == nullptr || egl.query_string == nullptr || egl.initialize == nullptr ||
      egl.bind_api == nullptr || egl.create_context == nullptr || egl.destroy_context == nullptr ||
      egl.make_current == nullptr || egl.get_error == nullptr) {
    return UnavailableError("egl: " + soname + " lacks EGL 1.4 core functions");
  }
  egl.get_platform_display =
      reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(egl.get_proc_address("eglGetPlatformDisplayEXT"));
  egl.query_devices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(egl.get_proc_address("eglQueryDevicesEXT"));
  egl.query_device_string =
      reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(egl.get_proc_address("eglQueryDeviceStringEXT"));
  if (egl.get_platform_display == nullptr) {
    return UnavailableError("egl: " + soname + " has no eglGetPlatformDisplayEXT (EGL_EXT_platform_base)");
  }
  return egl;
}

bool HasExtension(const char* extensions, std::string_view name) {
  if (extensions == nullptr) return false;
  const std::string_view all(extensions);
  for (size_t at = all.find(name); at != std::string_view::npos; at = all.find(name, at + 1)) {
    const bool starts = at == 0 || all[at - 1] == ' ';
    const bool ends = at + name.size() == all.size() || all[at + name.size()] == ' ';
    if (starts && ends) return true;
  }
  return false;
}

std::string EglErrorName(EGLint error) {
  switch (error) {
    case EGL_NOT_INITIALIZED:
      return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS:
      return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC:
      return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE:
      return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG:
      return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT:
      return "EGL_BAD_CONTEXT";
    case EGL_BAD_DISPLAY:
      return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH:
      return "EGL_BAD_MATCH";
    case EGL_BAD_PARAMETER:
      return "EGL_BAD_PARAMETER";
    default: {
      char text[32];
      std::snprintf(text, sizeof(text), "EGL error 0x%x", static_cast<unsigned>(error));
      return text;
    }
  }
}

// The display is never terminated: EGL displays are shared process-wide per platform, and
// eglTerminate would pull the ground from under every other context on it.
class EglContext final : public GlContext {
 public:
  EglContext(EglLibrary egl, EGLDisplay display, EGLContext context)
      : egl_(egl), display_(display), context_(context) {}
  ~EglContext() override {
    ReleaseCurrent();
    egl_.destroy_context(display_, context_);
  }

  Status MakeCurrent() override {
    if (!egl_.make_current(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_)) {
      return UnavailableError("egl: eglMakeCurrent failed: " + EglErrorName(egl_.get_error()));
    }
    return OkStatus();
  }
  void ReleaseCurrent() override { egl_.make_current(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT); }

  Status Init(std::string platform, bool allow_software) {
    PX_RETURN_IF_ERROR(MakeCurrent());
    auto resolve = [get = egl_.get_proc_address](const char* name) { return reinterpret_cast<void*>(get(name)); };
    return LoadFunctionsAndInfo(resolve, std::move(platform), allow_software);
  }

 private:
  EglLibrary egl_;
  EGLDisplay display_;
  EGLContext context_;
};

// Initialises `display` and creates a current, surfaceless desktop GL core context on it.
StatusOr<std::unique_ptr<GlContext>> ContextOnDisplay(const EglLibrary& egl,
                                                      EGLDisplay display,
                                                      const std::string& platform,
                                                      const GlContextOptions& options) {
  if (display == EGL_NO_DISPLAY)
    return UnavailableError(platform + ": no display (" + EglErrorName(egl.get_error()) + ")");
  EGLint major = 0;
  EGLint minor = 0;
  if (!egl.initialize(display, &major, &minor)) {
    return UnavailableError(platform + ": eglInitialize failed: " + EglErrorName(egl.get_error()));
  }
  const char* extensions = egl.query_string(display, EGL_EXTENSIONS);
  for (const char* needed : {"EGL_KHR_surfaceless_context", "EGL_KHR_create_context"}) {
    if (!HasExtension(extensions, needed)) return UnavailableError(platform + ": the display lacks " + needed);
  }
  // Without EGL_KHR_no_config_context a config is needed even for FBO-only rendering.
  if (!HasExtension(extensions, "EGL_KHR_no_config_context") &&
      !HasExtension(extensions, "EGL_MESA_configless_context")) {
    return UnavailableError(platform + ": the display lacks EGL_KHR_no_config_context");
  }
  if (!egl.bind_api(EGL_OPENGL_API)) {
    return UnavailableError(platform + ": desktop OpenGL is not offered (eglBindAPI: " + EglErrorName(egl.get_error()) +
                            ")");
  }
  const EGLint attribs[] = {EGL_CONTEXT_MAJOR_VERSION,
                            options.gl_major,
                            EGL_CONTEXT_MINOR_VERSION,
                            options.gl_minor,
                            EGL_CONTEXT_OPENGL_PROFILE_MASK,
                            EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                            EGL_NONE};
  EGLContext context = egl.create_context(display, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attribs);
  if (context == EGL_NO_CONTEXT) {
    return UnavailableError(platform + ": eglCreateContext refused a GL " + std::to_string(options.gl_major) + "." +
                            std::to_string(options.gl_minor) + " core context (" + EglErrorName(egl.get_error()) + ")");
  }
  auto made = std::make_unique<EglContext>(egl, display, context);
  PX_RETURN_IF_ERROR(made->Init(platform, options.allow_software));
  return std::unique_ptr<GlContext>(std::move(made));
}

// The first non-software EGL device that gives a context; NOT_FOUND when there is none.
StatusOr<std::unique_ptr<GlContext>> ContextOnGpuDevice(const EglLibrary& egl, const GlContextOptions& options) {
  const char* client_extensions = egl.query_string(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (egl.query_devices == nullptr || egl.query_device_string == nullptr ||
      !HasExtension(client_extensions, "EGL_EXT_platform_device")) {
    return NotFoundError("egl-device: device enumeration is not offered");
  }
  std::array<EGLDeviceEXT, 16> devices{};
  EGLint count = 0;
  if (!egl.query_devices(static_cast<EGLint>(devices.size()), devices.data(), &count) || count == 0) {
    return NotFoundError("egl-device: no EGL devices");
  }
  std::string reasons;
  for (EGLint i = 0; i < count; ++i) {
    const char* device_extensions = egl.query_device_string(devices[i], EGL_EXTENSIONS);
    if (HasExtension(device_extensions, "EGL_MESA_device_software")) continue;  // llvmpipe: surfaceless does that
    EGLDisplay display = egl.get_platform_display(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
    StatusOr<std::unique_ptr<GlContext>> context = ContextOnDisplay(egl, display, "egl-device", options);
    if (context.ok()) return context;
    reasons +=
        (reasons.empty() ? "" : "; ") + std::string("device ") + std::to_string(i) + ": " + context.status().message();
  }
  return NotFoundError("egl-device: no GPU device gave a context" + (reasons.empty() ? "" : " (" + reasons + ")"));
}

}  // namespace

StatusOr<std::unique_ptr<GlContext>> CreateEglContext(const GlContextOptions& options) {
  PX_RETURN_IF_ERROR(options.Validate());
  PX_ASSIGN_OR_RETURN(EglLibrary egl, LoadEgl(options.egl_library));
  StatusOr<std::unique_ptr<GlContext>> gpu = ContextOnGpuDevice(egl, options);
  if (gpu.ok()) return gpu;
  const char* client_extensions = egl.query_string(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (!HasExtension(client_extensions, "EGL_MESA_platform_surfaceless")) {
    return UnavailableError(gpu.status().message() + "; egl-surfaceless: EGL_MESA_platform_surfaceless is not offered");
  }
  EGLDisplay display = egl.get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  StatusOr<std::unique_ptr<GlContext>> surfaceless = ContextOnDisplay(egl, display, "egl-surfaceless", options);
  if (surfaceless.ok()) return surfaceless;
  return UnavailableError(gpu.status().message() + "; " + surfaceless.status().message());
}

}  // namespace px::render::gl
