// GLSL programs: compiled and linked with errors that name the program, the stage and the
// compiler's own log (the first lines, which name the line and the problem).
#pragma once

#include <string>
#include <string_view>

#include "pipeline/core/status.h"
#include "pipeline/render/gl/gl_functions.h"
#include "pipeline/render/gl/gl_objects.h"

namespace px::render::gl {

// Every shader starts with this (GLSL 3.30 core: the same text on OSMesa, EGL and GPU drivers).
inline constexpr std::string_view kGlslVersion = "#version 330 core\n";

// Compiles `vertex_source` and `fragment_source` (without the #version line) and links them.
// Errors are INTERNAL: "program soft_z: fragment shader: 0:12(3): error: ...".
StatusOr<GlObject> BuildProgram(const GlFunctions& gl,
                                std::string_view name,
                                std::string_view vertex_source,
                                std::string_view fragment_source);

}  // namespace px::render::gl
