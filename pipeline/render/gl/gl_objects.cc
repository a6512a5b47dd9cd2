#include "pipeline/render/gl/gl_objects.h"

#include <cstdio>

namespace px::render::gl {

GlObject::GlObject(const GlFunctions* gl, GlObjectKind kind) : gl_(gl), kind_(kind) {
  switch (kind) {
    case GlObjectKind::kTexture:
      gl->GenTextures(1, &id_);
      break;
    case GlObjectKind::kFramebuffer:
      gl->GenFramebuffers(1, &id_);
      break;
    case GlObjectKind::kBuffer:
      gl->GenBuffers(1, &id_);
      break;
    case GlObjectKind::kVertexArray:
      gl->GenVertexArrays(1, &id_);
      break;
    case GlObjectKind::kProgram:
      id_ = gl->CreateProgram();
      break;
  }
}

GlObject GlObject::Adopt(const GlFunctions* gl, GlObjectKind kind, GLuint id) {
  GlObject object;
  object.gl_ = gl;
  object.kind_ = kind;
  object.id_ = id;
  return object;
}

void GlObject::Reset() {
  if (id_ == 0 || gl_ == nullptr) return;
  switch (kind_) {
    case GlObjectKind::kTexture:
      gl_->DeleteTextures(1, &id_);
      break;
    case GlObjectKind::kFramebuffer:
      gl_->DeleteFramebuffers(1, &id_);
      break;
    case GlObjectKind::kBuffer:
      gl_->DeleteBuffers(1, &id_);
      break;
    case GlObjectKind::kVertexArray:
      gl_->DeleteVertexArrays(1, &id_);
      break;
    case GlObjectKind::kProgram:
      gl_->DeleteProgram(id_);
      break;
  }
  id_ = 0;
}

StatusOr<GlObject> MakeTexture2D(
    const GlFunctions& gl, GLenum internal_format, int width, int height, const std::string& what) {
  GLint max_size = 0;
  gl.GetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
  if (width < 1 || height < 1 || width > max_size || height > max_size) {
    return InvalidArgumentError(what + ": " + std::to_string(width) + "x" + std::to_string(height) +
                                " is outside what the GL context allows (1x1 .. " + std::to_string(max_size) + "x" +
                                std::to_string(max_size) + ")");
  }
  GlObject texture(&gl, GlObjectKind::kTexture);
  gl.BindTexture(GL_TEXTURE_2D, texture.id());
  // Storage format and type only matter for the (absent) initial data.
  const bool integer = internal_format == GL_R32I || internal_format == GL_RG32I || internal_format == GL_RGBA32I ||
                       internal_format == GL_RGBA32UI;
  gl.TexImage2D(GL_TEXTURE_2D,
                0,
                static_cast<GLint>(internal_format),
                width,
                height,
                0,
                integer ? GL_RED_INTEGER : GL_RED,
                integer ? GL_INT : GL_FLOAT,
                nullptr);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  gl.BindTexture(GL_TEXTURE_2D, 0);
  const std::string errors = DrainGlErrors(gl);
  if (!errors.empty()) {
    return ResourceExhaustedError(what + ": allocating a " + std::to_string(width) + "x" + std::to_string(height) +
                                  " texture raised " + errors);
  }
  return texture;
}

StatusOr<GlObject> MakeFramebuffer(const GlFunctions& gl,
                                   std::initializer_list<GLuint> colour_textures,
                                   const std::string& what) {
  GlObject framebuffer(&gl, GlObjectKind::kFramebuffer);
  gl.BindFramebuffer(GL_FRAMEBUFFER, framebuffer.id());
  GLenum buffers[8];
  int n = 0;
  for (GLuint texture : colour_textures) {
    if (n == 8) return InvalidArgumentError(what + ": more than 8 colour attachments");
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0 + n, GL_TEXTURE_2D, texture, 0);
    buffers[n] = GL_COLOR_ATTACHMENT0 + n;
    ++n;
  }
  gl.DrawBuffers(n, buffers);
  const GLenum status = gl.CheckFramebufferStatus(GL_FRAMEBUFFER);
  gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    char code[16];
    std::snprintf(code, sizeof(code), "0x%04x", status);
    return UnavailableError(what + ": framebuffer incomplete (status " + code + ")");
  }
  return framebuffer;
}

void ReadAttachment(
    const GlFunctions& gl, int attachment, int width, int height, GLenum format, GLenum type, void* out) {
  gl.ReadBuffer(GL_COLOR_ATTACHMENT0 + attachment);
  gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
  gl.ReadPixels(0, 0, width, height, format, type, out);
}

}  // namespace px::render::gl
