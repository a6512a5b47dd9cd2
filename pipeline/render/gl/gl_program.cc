#include "pipeline/render/gl/gl_program.h"

#include <vector>

namespace px::render::gl {
namespace {

// The log, trimmed: drivers append blank lines, and a long log buries its first error.
std::string TrimLog(std::string log) {
  while (!log.empty() && (log.back() == '\n' || log.back() == '\0' || log.back() == ' ')) log.pop_back();
  constexpr size_t kMaxChars = 600;
  if (log.size() > kMaxChars) log = log.substr(0, kMaxChars) + " ...";
  return log.empty() ? "(no log)" : log;
}

StatusOr<GLuint> Compile(const GlFunctions& gl, GLenum stage, std::string_view program, std::string_view source) {
  const char* stage_name = stage == GL_VERTEX_SHADER ? "vertex shader" : "fragment shader";
  const GLuint shader = gl.CreateShader(stage);
  if (shader == 0) return InternalError("program " + std::string(program) + ": glCreateShader failed");
  const char* parts[2] = {kGlslVersion.data(), source.data()};
  const GLint lengths[2] = {static_cast<GLint>(kGlslVersion.size()), static_cast<GLint>(source.size())};
  gl.ShaderSource(shader, 2, parts, lengths);
  gl.CompileShader(shader);
  GLint ok = GL_FALSE;
  gl.GetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (ok != GL_TRUE) {
    GLint length = 0;
    gl.GetShaderiv(shader, GL_INFO_LOG_LENGTH, &length);
    std::string log(static_cast<size_t>(std::max(length, 1)), '\0');
    gl.GetShaderInfoLog(shader, length, nullptr, log.data());
    gl.DeleteShader(shader);
    return InternalError("program " + std::string(program) + ": " + stage_name +
                         " does not compile: " + TrimLog(std::move(log)));
  }
  return shader;
}

}  // namespace

StatusOr<GlObject> BuildProgram(const GlFunctions& gl,
                                std::string_view name,
                                std::string_view vertex_source,
                                std::string_view fragment_source) {
  PX_ASSIGN_OR_RETURN(GLuint vertex, Compile(gl, GL_VERTEX_SHADER, name, vertex_source));
  StatusOr<GLuint> fragment = Compile(gl, GL_FRAGMENT_SHADER, name, fragment_source);
  if (!fragment.ok()) {
    gl.DeleteShader(vertex);
    return fragment.status();
  }
  GlObject program(&gl, GlObjectKind::kProgram);
  gl.AttachShader(program.id(), vertex);
  gl.AttachShader(program.id(), *fragment);
  gl.LinkProgram(program.id());
  gl.DeleteShader(vertex);  // flagged: freed with the program
  gl.DeleteShader(*fragment);
  GLint ok = GL_FALSE;
  gl.GetProgramiv(program.id(), GL_LINK_STATUS, &ok);
  if (ok != GL_TRUE) {
    GLint length = 0;
    gl.GetProgramiv(program.id(), GL_INFO_LOG_LENGTH, &length);
    std::string log(static_cast<size_t>(std::max(length, 1)), '\0');
    gl.GetProgramInfoLog(program.id(), length, nullptr, log.data());
    return InternalError("program " + std::string(name) + ": does not link: " + TrimLog(std::move(log)));
  }
  return program;
}

}  // namespace px::render::gl
