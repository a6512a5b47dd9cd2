// The GL entry points the GL back end uses, resolved at run time through the context's own
// GetProcAddress (OSMesaGetProcAddress or eglGetProcAddress). Nothing here links libGL,
// libOpenGL or libOSMesa: a binary that links glvnd's libOpenGL ahead of libOSMesa sends every
// GL call to a context-less dispatcher that silently does nothing (../shared/PLATFORM.md), and a machine
// without any GL library must still start and fall back to the CPU back end. One table per
// context: the two platforms' entry points are different functions.
#pragma once

#include <GL/glcorearb.h>

#include <functional>

#include "pipeline/core/status.h"

namespace px::render::gl {

// X-macro: every function the back end calls, with its <GL/glcorearb.h> pointer type. GL 3.3
// core is enough for all of them (the context asks for 3.3 core or newer).
#define PX_GL_FUNCTIONS(X)                                     \
  X(PFNGLGETSTRINGPROC, GetString)                             \
  X(PFNGLGETSTRINGIPROC, GetStringi)                           \
  X(PFNGLGETINTEGERVPROC, GetIntegerv)                         \
  X(PFNGLGETERRORPROC, GetError)                               \
  X(PFNGLENABLEPROC, Enable)                                   \
  X(PFNGLDISABLEPROC, Disable)                                 \
  X(PFNGLSCISSORPROC, Scissor)                                 \
  X(PFNGLVIEWPORTPROC, Viewport)                               \
  X(PFNGLCLEARBUFFERFVPROC, ClearBufferfv)                     \
  X(PFNGLBLENDFUNCSEPARATEPROC, BlendFuncSeparate)             \
  X(PFNGLBLENDEQUATIONPROC, BlendEquation)                     \
  X(PFNGLFINISHPROC, Finish)                                   \
  X(PFNGLPIXELSTOREIPROC, PixelStorei)                         \
  X(PFNGLREADPIXELSPROC, ReadPixels)                           \
  X(PFNGLREADBUFFERPROC, ReadBuffer)                           \
  X(PFNGLDRAWBUFFERSPROC, DrawBuffers)                         \
  X(PFNGLGENTEXTURESPROC, GenTextures)                         \
  X(PFNGLDELETETEXTURESPROC, DeleteTextures)                   \
  X(PFNGLBINDTEXTUREPROC, BindTexture)                         \
  X(PFNGLACTIVETEXTUREPROC, ActiveTexture)                     \
  X(PFNGLTEXIMAGE2DPROC, TexImage2D)                           \
  X(PFNGLTEXSUBIMAGE2DPROC, TexSubImage2D)                     \
  X(PFNGLTEXIMAGE3DPROC, TexImage3D)                           \
  X(PFNGLTEXSUBIMAGE3DPROC, TexSubImage3D)                     \
  X(PFNGLTEXPARAMETERIPROC, TexParameteri)                     \
  X(PFNGLGENFRAMEBUFFERSPROC, GenFramebuffers)                 \
  X(PFNGLDELETEFRAMEBUFFERSPROC, DeleteFramebuffers)           \
  X(PFNGLBINDFRAMEBUFFERPROC, BindFramebuffer)                 \
  X(PFNGLFRAMEBUFFERTEXTURE2DPROC, FramebufferTexture2D)       \
  X(PFNGLFRAMEBUFFERTEXTURELAYERPROC, FramebufferTextureLayer) \
  X(PFNGLCHECKFRAMEBUFFERSTATUSPROC, CheckFramebufferStatus)   \
  X(PFNGLGENBUFFERSPROC, GenBuffers)                           \
  X(PFNGLDELETEBUFFERSPROC, DeleteBuffers)                     \
  X(PFNGLBINDBUFFERPROC, BindBuffer)                           \
  X(PFNGLBUFFERDATAPROC, BufferData)                           \
  X(PFNGLGENVERTEXARRAYSPROC, GenVertexArrays)                 \
  X(PFNGLDELETEVERTEXARRAYSPROC, DeleteVertexArrays)           \
  X(PFNGLBINDVERTEXARRAYPROC, BindVertexArray)                 \
  X(PFNGLVERTEXATTRIBPOINTERPROC, VertexAttribPointer)         \
  X(PFNGLVERTEXATTRIBIPOINTERPROC, VertexAttribIPointer)       \
  X(PFNGLENABLEVERTEXATTRIBARRAYPROC, EnableVertexAttribArray) \
  X(PFNGLVERTEXATTRIBDIVISORPROC, VertexAttribDivisor)         \
  X(PFNGLDRAWARRAYSPROC, DrawArrays)                           \
  X(PFNGLDRAWARRAYSINSTANCEDPROC, DrawArraysInstanced)         \
  X(PFNGLCREATESHADERPROC, CreateShader)                       \
  X(PFNGLSHADERSOURCEPROC, ShaderSource)                       \
  X(PFNGLCOMPILESHADERPROC, CompileShader)                     \
  X(PFNGLGETSHADERIVPROC, GetShaderiv)                         \
  X(PFNGLGETSHADERINFOLOGPROC, GetShaderInfoLog)               \
  X(PFNGLDELETESHADERPROC, DeleteShader)                       \
  X(PFNGLCREATEPROGRAMPROC, CreateProgram)                     \
  X(PFNGLATTACHSHADERPROC, AttachShader)                       \
  X(PFNGLLINKPROGRAMPROC, LinkProgram)                         \
  X(PFNGLGETPROGRAMIVPROC, GetProgramiv)                       \
  X(PFNGLGETPROGRAMINFOLOGPROC, GetProgramInfoLog)             \
  X(PFNGLDELETEPROGRAMPROC, DeleteProgram)                     \
  X(PFNGLUSEPROGRAMPROC, UseProgram)                           \
  X(PFNGLGETUNIFORMLOCATIONPROC, GetUniformLocation)           \
  X(PFNGLUNIFORM1IPROC, Uniform1i)                             \
  X(PFNGLUNIFORM1FPROC, Uniform1f)                             \
  X(PFNGLUNIFORM2FPROC, Uniform2f)                             \
  X(PFNGLUNIFORM3FPROC, Uniform3f)                             \
  X(PFNGLUNIFORM4FPROC, Uniform4f)                             \
  X(PFNGLUNIFORM1IVPROC, Uniform1iv)                           \
  X(PFNGLUNIFORM1FVPROC, Uniform1fv)                           \
  X(PFNGLUNIFORM2FVPROC, Uniform2fv)                           \
  X(PFNGLUNIFORM3FVPROC, Uniform3fv)                           \
  X(PFNGLUNIFORM4FVPROC, Uniform4fv)                           \
  X(PFNGLUNIFORMMATRIX3FVPROC, UniformMatrix3fv)               \
  X(PFNGLUNIFORMMATRIX4FVPROC, UniformMatrix4fv)

struct GlFunctions {
#define PX_GL_DECLARE(type, name) type name = nullptr;
  PX_GL_FUNCTIONS(PX_GL_DECLARE)
#undef PX_GL_DECLARE
};

// Resolves a GL function by its full name ("glGetString"); nullptr when the platform lacks it.
using GlProcResolver = std::function<void*(const char* name)>;

// Fills every entry. Errors name the first function the platform could not resolve.
StatusOr<GlFunctions> LoadGlFunctions(const GlProcResolver& resolve, std::string_view platform);

// The GL error flags raised since the last call ("GL_INVALID_OPERATION, GL_OUT_OF_MEMORY"), or
// "" when none; clears them.
std::string DrainGlErrors(const GlFunctions& gl);

}  // namespace px::render::gl
