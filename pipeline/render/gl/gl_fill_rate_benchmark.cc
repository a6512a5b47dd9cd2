// The floor of a GL pass on this machine (llvmpipe on OSMesa, or EGL: PX_GL=egl|osmesa picks):
// the process CPU time of drawing with a shader that writes a constant, by target format
// (RGBA8, RGBA16, RGBA16F, RGBA32F), texel fetches per fragment, primitive size (one full-screen triangle, or 10x10 px
// rectangles overlapping to 3.2 fragments a pixel as the segment pass draws them) and with or
// without an 8-bit (RGBA8) or float read-back. What no shader work can go below: the renderer's
// design needs a weights pass, ~3.2 fragments a pixel of segments and a resolve. Prints
// ns_per_pixel (process CPU per output pixel per pass); asserts nothing.
#include <benchmark/benchmark.h>
#include <time.h>

#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "pipeline/render/gl/gl_context.h"
#include "pipeline/render/gl/gl_objects.h"
#include "pipeline/render/gl/gl_program.h"
#include "pipeline/render/gl/gl_render_shaders.h"

namespace px::render::gl {
namespace {

double ProcessCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// Instance i is a `tile` px square at grid cell i of a `columns`-wide grid with `step` px pitch.
constexpr std::string_view kTileVertex = R"(
uniform vec2 viewport_size;
uniform int columns;
uniform float step_px;
uniform float tile_px;
void main() {
  vec2 corner = vec2(gl_VertexID & 1, gl_VertexID >> 1) * tile_px;
  vec2 origin = vec2(gl_InstanceID % columns, gl_InstanceID / columns) * step_px;
  gl_Position = vec4((origin + corner) / viewport_size * 2.0 - 1.0, 0.0, 1.0);
}
)";

constexpr std::string_view kConstantFragment = R"(
layout(location = 0) out vec4 colour;
void main() { colour = vec4(0.25, 0.5, 0.75, 1.0); }
)";

// FETCHES texelFetch calls from a texture of the target's format at neighbouring texels, summed
// (the segment shader makes 5 per fragment, the resolve 7 per pixel).
constexpr std::string_view kFetchFragment = R"(
uniform sampler2D source;
layout(location = 0) out vec4 colour;
void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  vec4 sum = vec4(0.0);
  for (int i = 0; i < FETCHES; ++i) sum += texelFetch(source, p + ivec2(i & 1, i >> 1), 0);
  colour = sum;
}
)";

struct Format {
  GLenum internal_format;
  const char* name;
  GLenum read_type;  // what a read-back asks for
};
constexpr Format kFormats[] = {{GL_RGBA8, "rgba8", GL_UNSIGNED_BYTE},
                               {GL_RGBA16, "rgba16", GL_UNSIGNED_BYTE},
                               {GL_RGBA16F, "rgba16f", GL_FLOAT},
                               {GL_RGBA32F, "rgba32f", GL_FLOAT}};

// range(0): width (height 2/3 of it); range(1): format index in kFormats; range(2): 0 one
// full-screen triangle, 1 overlapping 10x10 px tiles (3.2 fragments a pixel); range(3): read back;
// range(4): texel fetches per fragment from a texture of the same format (0: a constant).
void BM_GlPassFloor(benchmark::State& state) {
  const int width = static_cast<int>(state.range(0)), height = width * 2 / 3;
  const Format& format = kFormats[state.range(1)];
  const bool tiles = state.range(2) != 0, read_back = state.range(3) != 0;
  const int fetches = static_cast<int>(state.range(4));
  GlContextOptions options;
  if (const char* name = std::getenv("PX_GL")) {
    if (auto platform = ParseGlPlatform(name); platform.ok()) options.platform = *platform;
  }
  auto context = CreateGlContext(options);
  if (!context.ok() || !(*context)->MakeCurrent().ok()) {
    state.SkipWithError(context.ok() ? "no current context" : context.status().ToString().c_str());
    return;
  }
  const GlFunctions& gl = (*context)->gl();
  {
    auto target = MakeTexture2D(gl, format.internal_format, width, height, "floor target");
    if (!target.ok()) {
      state.SkipWithError(target.status().ToString().c_str());
      return;
    }
    auto fbo = MakeFramebuffer(gl, {target->id()}, "floor");
    auto source = MakeTexture2D(gl, format.internal_format, width + 2, height + 2, "floor source");
    const std::string fetch_shader = "#define FETCHES " + std::to_string(fetches) + "\n" + std::string(kFetchFragment);
    auto program = BuildProgram(gl,
                                "floor",
                                tiles ? kTileVertex : kFullScreenVertexShader,
                                fetches > 0 ? std::string_view(fetch_shader) : kConstantFragment);
    if (!source.ok()) {
      state.SkipWithError(source.status().ToString().c_str());
      return;
    }
    if (!fbo.ok() || !program.ok()) {
      state.SkipWithError(!fbo.ok() ? fbo.status().ToString().c_str() : program.status().ToString().c_str());
      return;
    }
    GlObject vertex_array(&gl, GlObjectKind::kVertexArray);
    gl.BindVertexArray(vertex_array.id());
    gl.BindFramebuffer(GL_FRAMEBUFFER, fbo->id());
    gl.Viewport(0, 0, width, height);
    gl.UseProgram(program->id());
    if (fetches > 0) {
      gl.ActiveTexture(GL_TEXTURE0);
      gl.BindTexture(GL_TEXTURE_2D, source->id());
      gl.Uniform1i(gl.GetUniformLocation(program->id(), "source"), 0);
    }
    // Tiles of 10 px every 5.6 px: (10 / 5.6)^2 = 3.2 fragments a pixel, as the segment pass.
    constexpr float kTilePx = 10.0f, kStepPx = 5.6f;
    const int columns = static_cast<int>(width / kStepPx) + 1, rows = static_cast<int>(height / kStepPx) + 1;
    if (tiles) {
      const GLuint p = program->id();
      gl.Uniform2f(gl.GetUniformLocation(p, "viewport_size"), static_cast<float>(width), static_cast<float>(height));
      gl.Uniform1i(gl.GetUniformLocation(p, "columns"), columns);
      gl.Uniform1f(gl.GetUniformLocation(p, "step_px"), kStepPx);
      gl.Uniform1f(gl.GetUniformLocation(p, "tile_px"), kTilePx);
    }
    std::vector<float> pixels(static_cast<size_t>(width) * height * 4);
    const auto draw = [&] {
      if (tiles) {
        gl.DrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, columns * rows);
      } else {
        gl.DrawArrays(GL_TRIANGLES, 0, 3);
      }
      if (read_back) ReadAttachment(gl, 0, width, height, GL_RGBA, format.read_type, pixels.data());
      gl.Finish();
    };
    draw();  // llvmpipe compiles the shader variant on first use
    const double cpu_start = ProcessCpuSeconds();
    long passes = 0;
    for (auto _ : state) {
      draw();
      ++passes;
    }
    const double cpu_s = ProcessCpuSeconds() - cpu_start;
    state.counters["ns_per_pixel"] = 1e9 * cpu_s / std::max(passes, 1L) / (static_cast<double>(width) * height);
    state.SetLabel(std::string(format.name) + (tiles ? " tiles" : " full-screen") + (read_back ? " + read-back" : "") +
                   (fetches > 0 ? ", " + std::to_string(fetches) + " fetches" : std::string()) + ", " +
                   (*context)->info().renderer);
  }
  (*context)->ReleaseCurrent();
}
BENCHMARK(BM_GlPassFloor)
    ->ArgNames({"width", "format", "tiles", "read", "fetches"})
    ->ArgsProduct({{480, 1200}, {0, 1, 2, 3}, {0}, {0}, {0}})
    ->ArgsProduct({{480, 1200}, {0, 3}, {1}, {0}, {0}})
    ->ArgsProduct({{480, 1200}, {0, 3}, {0}, {1}, {0}})
    ->ArgsProduct({{480, 1200}, {0, 3}, {0}, {0}, {1, 4}})
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

}  // namespace
}  // namespace px::render::gl
