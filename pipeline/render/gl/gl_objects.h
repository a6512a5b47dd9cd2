// Move-only owners of GL objects (textures, framebuffers, buffers, vertex arrays, programs),
// deleted through the context's function table. They must be destroyed while their context is
// current (the renderer makes it current for its destructor).
#pragma once

#include <string>
#include <utility>

#include "pipeline/core/status.h"
#include "pipeline/render/gl/gl_functions.h"

namespace px::render::gl {

enum class GlObjectKind { kTexture, kFramebuffer, kBuffer, kVertexArray, kProgram };

class GlObject {
 public:
  GlObject() = default;
  GlObject(const GlFunctions* gl, GlObjectKind kind);  // generates one object of `kind`
  ~GlObject() { Reset(); }
  GlObject(GlObject&& other) noexcept { *this = std::move(other); }
  GlObject& operator=(GlObject&& other) noexcept {
    if (this != &other) {
      Reset();
      gl_ = std::exchange(other.gl_, nullptr);
      kind_ = other.kind_;
      id_ = std::exchange(other.id_, 0);
    }
    return *this;
  }
  GlObject(const GlObject&) = delete;
  GlObject& operator=(const GlObject&) = delete;

  GLuint id() const { return id_; }
  explicit operator bool() const { return id_ != 0; }
  void Reset();
  // Takes ownership of an id made elsewhere (glCreateProgram).
  static GlObject Adopt(const GlFunctions* gl, GlObjectKind kind, GLuint id);

 private:
  const GlFunctions* gl_ = nullptr;
  GlObjectKind kind_ = GlObjectKind::kTexture;
  GLuint id_ = 0;
};

// A 2D texture of `internal_format` (GL_RGBA8, GL_RGBA32F, GL_R32F, ...) with nearest filtering
// and clamped edges, uninitialised. Errors name `what` and the size.
StatusOr<GlObject> MakeTexture2D(
    const GlFunctions& gl, GLenum internal_format, int width, int height, const std::string& what);

// A framebuffer with the given textures as colour attachments 0..n-1, checked complete.
StatusOr<GlObject> MakeFramebuffer(const GlFunctions& gl,
                                   std::initializer_list<GLuint> colour_textures,
                                   const std::string& what);

// Reads attachment `attachment` of the bound read framebuffer: `format`/`type` as glReadPixels
// (GL_RGBA/GL_FLOAT, GL_RED/GL_FLOAT, GL_RGBA/GL_UNSIGNED_BYTE) into `out` (rows bottom-up as GL
// stores them; the caller flips if it wants).
void ReadAttachment(
    const GlFunctions& gl, int attachment, int width, int height, GLenum format, GLenum type, void* out);

}  // namespace px::render::gl
