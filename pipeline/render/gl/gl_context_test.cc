#include "pipeline/render/gl/gl_context.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <string>
#include <thread>
#include <vector>

#include "pipeline/render/gl/gl_objects.h"
#include "pipeline/render/gl/gl_program.h"

namespace px::render::gl {
namespace {

using ::testing::HasSubstr;

GlContextOptions OptionsFor(GlPlatform platform) {
  GlContextOptions options;
  options.platform = platform;
  return options;
}

// A full-screen triangle whose fragment shader writes values no 8-bit target can hold, so the
// read-back proves the float path end to end.
constexpr std::string_view kFullScreenVertex = R"(
const vec2 kCorners[3] = vec2[3](vec2(-1.0, -1.0), vec2(3.0, -1.0), vec2(-1.0, 3.0));
void main() { gl_Position = vec4(kCorners[gl_VertexID], 0.0, 1.0); }
)";
constexpr std::string_view kFloatFragment = R"(
uniform float scale;
out vec4 colour;
void main() { colour = vec4(gl_FragCoord.x * scale, gl_FragCoord.y, -1.5, 1e6); }
)";

class GlContextPlatformTest : public ::testing::TestWithParam<GlPlatform> {};

TEST_P(GlContextPlatformTest, RendersToAFloatFramebufferAndReadsItBack) {
  StatusOr<std::unique_ptr<GlContext>> context = CreateGlContext(OptionsFor(GetParam()));
  ASSERT_TRUE(context.ok()) << context.status().ToString();
  const GlContextInfo& info = (*context)->info();
  std::printf("%s\n", info.ToString().c_str());
  EXPECT_GE(info.max_texture_size, 2048);
  EXPECT_GE(info.max_array_texture_layers, 256);
  EXPECT_EQ((*context)->BackendName(), GetParam() == GlPlatform::kOsmesa ? "gl-osmesa" : "gl-egl");

  const GlFunctions& gl = (*context)->gl();
  constexpr int kWidth = 7;
  constexpr int kHeight = 5;
  StatusOr<GlObject> texture = MakeTexture2D(gl, GL_RGBA32F, kWidth, kHeight, "test target");
  ASSERT_TRUE(texture.ok()) << texture.status().ToString();
  StatusOr<GlObject> framebuffer = MakeFramebuffer(gl, {texture->id()}, "test framebuffer");
  ASSERT_TRUE(framebuffer.ok()) << framebuffer.status().ToString();
  StatusOr<GlObject> program = BuildProgram(gl, "float_test", kFullScreenVertex, kFloatFragment);
  ASSERT_TRUE(program.ok()) << program.status().ToString();
  GlObject vertex_array(&gl, GlObjectKind::kVertexArray);

  gl.BindFramebuffer(GL_FRAMEBUFFER, framebuffer->id());
  gl.Viewport(0, 0, kWidth, kHeight);
  gl.UseProgram(program->id());
  gl.Uniform1f(gl.GetUniformLocation(program->id(), "scale"), 0.125f);
  gl.BindVertexArray(vertex_array.id());
  gl.DrawArrays(GL_TRIANGLES, 0, 3);
  std::vector<std::array<float, 4>> pixels(kWidth * kHeight);
  ReadAttachment(gl, 0, kWidth, kHeight, GL_RGBA, GL_FLOAT, pixels.data());
  EXPECT_EQ(DrainGlErrors(gl), "");
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      const std::array<float, 4>& p = pixels[y * kWidth + x];
      // Fragment centres are at half-integers: exact in float.
      EXPECT_EQ(p[0], (x + 0.5f) * 0.125f) << x << "," << y;
      EXPECT_EQ(p[1], y + 0.5f);
      EXPECT_EQ(p[2], -1.5f);
      EXPECT_EQ(p[3], 1e6f);
    }
  }
}

TEST_P(GlContextPlatformTest, MovesBetweenThreads) {
  StatusOr<std::unique_ptr<GlContext>> context = CreateGlContext(OptionsFor(GetParam()));
  ASSERT_TRUE(context.ok()) << context.status().ToString();
  (*context)->ReleaseCurrent();
  std::string renderer;
  std::thread worker([&] {
    ScopedCurrent current(context->get());
    ASSERT_TRUE(current.status().ok()) << current.status().ToString();
    renderer = reinterpret_cast<const char*>((*context)->gl().GetString(GL_RENDERER));
  });
  worker.join();
  EXPECT_EQ(renderer, (*context)->info().renderer);
}

TEST_P(GlContextPlatformTest, ShaderErrorsNameTheProgramStageAndLine) {
  StatusOr<std::unique_ptr<GlContext>> context = CreateGlContext(OptionsFor(GetParam()));
  ASSERT_TRUE(context.ok()) << context.status().ToString();
  const GlFunctions& gl = (*context)->gl();
  StatusOr<GlObject> broken = BuildProgram(gl, "broken", kFullScreenVertex, "out vec4 c;\nvoid main() { c = nope; }\n");
  ASSERT_FALSE(broken.ok());
  EXPECT_EQ(broken.status().code(), StatusCode::kInternal);
  EXPECT_THAT(broken.status().message(), HasSubstr("program broken: fragment shader does not compile"));
  EXPECT_THAT(broken.status().message(), HasSubstr("nope"));
  // Linking fails when the stages disagree on an interface variable's type.
  StatusOr<GlObject> unlinked = BuildProgram(gl,
                                             "mismatch",
                                             "out float v;\nvoid main() { v = 1.0; gl_Position = vec4(0.0); }\n",
                                             "in vec2 v;\nout vec4 c;\nvoid main() { c = vec4(v, 0.0, 1.0); }\n");
  ASSERT_FALSE(unlinked.ok());
  EXPECT_THAT(unlinked.status().message(), HasSubstr("program mismatch: does not link"));
}

TEST_P(GlContextPlatformTest, TexturesTooLargeForTheContextAreRefusedByName) {
  StatusOr<std::unique_ptr<GlContext>> context = CreateGlContext(OptionsFor(GetParam()));
  ASSERT_TRUE(context.ok()) << context.status().ToString();
  const int too_big = (*context)->info().max_texture_size + 1;
  StatusOr<GlObject> texture = MakeTexture2D((*context)->gl(), GL_RGBA8, too_big, 4, "frame colour");
  ASSERT_FALSE(texture.ok());
  EXPECT_EQ(texture.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(texture.status().message(), HasSubstr("frame colour: " + std::to_string(too_big) + "x4"));
  EXPECT_FALSE(MakeTexture2D((*context)->gl(), GL_RGBA8, 0, 4, "empty").ok());
}

TEST_P(GlContextPlatformTest, SoftwareIsRefusedWhenNotAllowed) {
  GlContextOptions options = OptionsFor(GetParam());
  options.allow_software = false;
  StatusOr<std::unique_ptr<GlContext>> context = CreateGlContext(options);
  if (context.ok()) {
    EXPECT_FALSE((*context)->info().software) << (*context)->info().ToString();
  } else {
    EXPECT_EQ(context.status().code(), StatusCode::kUnavailable);
    EXPECT_THAT(context.status().message(), HasSubstr("software"));
  }
}

TEST_P(GlContextPlatformTest, AnUnavailableVersionFailsWithTheVersion) {
  GlContextOptions options = OptionsFor(GetParam());
  options.gl_major = 4;
  options.gl_minor = 6;
  StatusOr<std::unique_ptr<GlContext>> context = CreateGlContext(options);
  if (context.ok()) {  // a driver with GL 4.6 (a GPU)
    EXPECT_THAT((*context)->info().version, HasSubstr("4.6"));
  } else {  // Mesa 22's llvmpipe stops at 4.5
    EXPECT_EQ(context.status().code(), StatusCode::kUnavailable);
    EXPECT_THAT(context.status().message(), HasSubstr("4.6 core context"));
  }
}

INSTANTIATE_TEST_SUITE_P(Platforms,
                         GlContextPlatformTest,
                         ::testing::Values(GlPlatform::kOsmesa, GlPlatform::kEgl),
                         [](const auto& param_info) { return std::string(GlPlatformName(param_info.param)); });

TEST(GlContextTest, AMissingLibraryIsNamedWithItsPackage) {
  GlContextOptions options = OptionsFor(GlPlatform::kOsmesa);
  options.osmesa_library = "libOSMesa-absent.so.8";
  StatusOr<std::unique_ptr<GlContext>> osmesa = CreateGlContext(options);
  ASSERT_FALSE(osmesa.ok());
  EXPECT_EQ(osmesa.status().code(), StatusCode::kUnavailable);
  EXPECT_THAT(osmesa.status().message(), HasSubstr("osmesa: cannot load libOSMesa-absent.so.8"));
  EXPECT_THAT(osmesa.status().message(), HasSubstr("libosmesa6"));

  options.platform = GlPlatform::kAuto;
  options.egl_library = "libEGL-absent.so.1";
  StatusOr<std::unique_ptr<GlContext>> none = CreateGlContext(options);
  ASSERT_FALSE(none.ok());
  EXPECT_THAT(none.status().message(), HasSubstr("no GL context"));
  EXPECT_THAT(none.status().message(), HasSubstr("libEGL-absent.so.1"));
  EXPECT_THAT(none.status().message(), HasSubstr("libOSMesa-absent.so.8"));
}

TEST(GlContextTest, AutoFallsBackToOsmesaWithoutEgl) {
  GlContextOptions options;
  options.egl_library = "libEGL-absent.so.1";
  StatusOr<std::unique_ptr<GlContext>> context = CreateGlContext(options);
  ASSERT_TRUE(context.ok()) << context.status().ToString();
  EXPECT_EQ((*context)->info().platform, "osmesa");
}

TEST(GlContextTest, OptionsAndNamesAreChecked) {
  GlContextOptions options;
  options.gl_major = 3;
  options.gl_minor = 2;
  EXPECT_THAT(options.Validate().message(), HasSubstr("3.2"));
  EXPECT_FALSE(CreateGlContext(options).ok());
  EXPECT_EQ(*ParseGlPlatform("egl"), GlPlatform::kEgl);
  EXPECT_EQ(*ParseGlPlatform("osmesa"), GlPlatform::kOsmesa);
  EXPECT_THAT(ParseGlPlatform("vulkan").status().message(), HasSubstr("\"vulkan\""));
}

}  // namespace
}  // namespace px::render::gl
