#include "pipeline/render/gl/gl_context.h"

#include <string>

namespace px::render::gl {

std::string_view GlPlatformName(GlPlatform platform) {
  switch (platform) {
    case GlPlatform::kAuto:
      return "auto";
    case GlPlatform::kEgl:
      return "egl";
    case GlPlatform::kOsmesa:
      return "osmesa";
  }
  return "?";
}

StatusOr<GlPlatform> ParseGlPlatform(std::string_view name) {
  for (GlPlatform platform : {GlPlatform::kAuto, GlPlatform::kEgl, GlPlatform::kOsmesa}) {
    if (name == GlPlatformName(platform)) return platform;
  }
  return InvalidArgumentError("GL platform \"" + std::string(name) + "\" is not one of auto, egl, osmesa");
}

Status GlContextOptions::Validate() const {
  const int version = gl_major * 10 + gl_minor;
  if (gl_major < 3 || gl_major > 4 || gl_minor < 0 || gl_minor > 6 || version < 33) {
    return InvalidArgumentError("GL version " + std::to_string(gl_major) + "." + std::to_string(gl_minor) +
                                " is outside [3.3, 4.6]");
  }
  if (egl_library.empty()) return InvalidArgumentError("egl_library is empty");
  if (osmesa_library.empty()) return InvalidArgumentError("osmesa_library is empty");
  return OkStatus();
}

std::string GlContextInfo::ToString() const {
  return platform + ": " + renderer + ", " + version + (software ? " (software)" : "");
}

std::string_view GlContext::BackendName() const {
  return info_.platform == "osmesa" ? std::string_view("gl-osmesa") : std::string_view("gl-egl");
}

Status GlContext::LoadFunctionsAndInfo(const GlProcResolver& resolve, std::string platform, bool allow_software) {
  PX_ASSIGN_OR_RETURN(gl_, LoadGlFunctions(resolve, platform));
  auto text = [&](GLenum name) {
    const GLubyte* value = gl_.GetString(name);
    return value == nullptr ? std::string("?") : std::string(reinterpret_cast<const char*>(value));
  };
  info_.platform = std::move(platform);
  info_.vendor = text(GL_VENDOR);
  info_.renderer = text(GL_RENDERER);
  info_.version = text(GL_VERSION);
  for (const char* software : {"llvmpipe", "softpipe", "swrast", "SWR"}) {
    if (info_.renderer.find(software) != std::string::npos) info_.software = true;
  }
  gl_.GetIntegerv(GL_MAX_TEXTURE_SIZE, &info_.max_texture_size);
  gl_.GetIntegerv(GL_MAX_ARRAY_TEXTURE_LAYERS, &info_.max_array_texture_layers);
  gl_.GetIntegerv(GL_MAX_DRAW_BUFFERS, &info_.max_draw_buffers);
  const std::string errors = DrainGlErrors(gl_);
  if (!errors.empty()) return InternalError(info_.platform + ": querying the new context raised " + errors);
  if (info_.software && !allow_software) {
    return UnavailableError(info_.platform + ": only a software rasteriser is available (" + info_.renderer +
                            ") and software GL is not allowed");
  }
  return OkStatus();
}

StatusOr<std::unique_ptr<GlContext>> CreateGlContext(const GlContextOptions& options) {
  PX_RETURN_IF_ERROR(options.Validate());
  switch (options.platform) {
    case GlPlatform::kEgl:
      return CreateEglContext(options);
    case GlPlatform::kOsmesa:
      return CreateOsmesaContext(options);
    case GlPlatform::kAuto:
      break;
  }
  StatusOr<std::unique_ptr<GlContext>> egl = CreateEglContext(options);
  if (egl.ok()) return egl;
  StatusOr<std::unique_ptr<GlContext>> osmesa = CreateOsmesaContext(options);
  if (osmesa.ok()) return osmesa;
  return UnavailableError("no GL context: " + egl.status().message() + "; " + osmesa.status().message());
}

}  // namespace px::render::gl
