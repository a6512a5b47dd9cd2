#include "pipeline/render/gl/gl_functions.h"

#include <string>

namespace px::render::gl {

StatusOr<GlFunctions> LoadGlFunctions(const GlProcResolver& resolve, std::string_view platform) {
  GlFunctions gl;
#define PX_GL_LOAD(type, name)                                                                \
  gl.name = reinterpret_cast<type>(resolve("gl" #name));                                      \
  if (gl.name == nullptr) {                                                                   \
    return UnavailableError(std::string(platform) + ": the GL implementation has no gl" #name \
                                                    " (GL 3.3 core "                          \
                                                    "is required)");                          \
  }
  PX_GL_FUNCTIONS(PX_GL_LOAD)
#undef PX_GL_LOAD
  return gl;
}

std::string DrainGlErrors(const GlFunctions& gl) {
  std::string errors;
  // A context that lost its device keeps returning the same error: stop after a few.
  for (int i = 0; i < 8; ++i) {
    const GLenum error = gl.GetError();
    if (error == GL_NO_ERROR) break;
    const char* name = "GL error";
    switch (error) {
      case GL_INVALID_ENUM:
        name = "GL_INVALID_ENUM";
        break;
      case GL_INVALID_VALUE:
        name = "GL_INVALID_VALUE";
        break;
      case GL_INVALID_OPERATION:
        name = "GL_INVALID_OPERATION";
        break;
      case GL_INVALID_FRAMEBUFFER_OPERATION:
        name = "GL_INVALID_FRAMEBUFFER_OPERATION";
        break;
      case GL_OUT_OF_MEMORY:
        name = "GL_OUT_OF_MEMORY";
        break;
      default:
        break;
    }
    if (!errors.empty()) errors += ", ";
    errors += name;
  }
  return errors;
}

}  // namespace px::render::gl
