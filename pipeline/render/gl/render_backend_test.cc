// The back-end choice on this kind of machine (no GPU: llvmpipe only) and when GL is missing.
#include "pipeline/render/gl/render_backend.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pipeline/render/gl/gl_scene_renderer.h"
#include "pipeline/render/gl/layered_plane_scene_testing.h"

namespace px::render::gl {
namespace {

using ::testing::HasSubstr;

TEST(RenderBackendTest, NamesParse) {
  for (RenderBackend b : {RenderBackend::kAuto, RenderBackend::kCpu, RenderBackend::kEgl, RenderBackend::kOsmesa}) {
    EXPECT_EQ(ParseRenderBackend(RenderBackendName(b)).value(), b);
  }
  EXPECT_EQ(ParseRenderBackend("vulkan").status().message(),
            "render backend: \"vulkan\" is not one of auto, cpu, egl, osmesa");
}

TEST(RenderBackendTest, AutoTakesGlOnlyWhenItIsHardware) {
  BackendChoice choice = ChooseRenderBackend(RenderBackend::kAuto);
  if (choice.backend == RenderBackend::kCpu) {
    EXPECT_EQ(choice.context, nullptr);
    EXPECT_THAT(choice.reason, HasSubstr("cpu: no hardware GL"));
  } else {  // a machine with a GPU
    ASSERT_NE(choice.context, nullptr);
    EXPECT_FALSE(choice.context->info().software);
  }
}

TEST(RenderBackendTest, ForcedGlGivesAContextTheRendererUses) {
  BackendChoice choice = ChooseRenderBackend(RenderBackend::kOsmesa);
  ASSERT_EQ(choice.backend, RenderBackend::kOsmesa) << choice.reason;
  ASSERT_NE(choice.context, nullptr);
  EXPECT_THAT(choice.reason, HasSubstr("gl-osmesa: asked for"));
  auto renderer = GlSceneRenderer::Create(
      testing::LayeredPlaneScene(render::testing::PlaneScene{}, 2, 2, 0.025, CameraModel::Pinhole(64, 48, 56)),
      std::move(choice.context));
  ASSERT_TRUE(renderer.ok()) << renderer.status().ToString();
  EXPECT_EQ((*renderer)->BackendName(), "gl-osmesa");
}

TEST(RenderBackendTest, MissingGlLibrariesFallBackToTheCpuWithTheReason) {
  GlContextOptions missing;
  missing.osmesa_library = "libOSMesa-not-here.so.8";
  missing.egl_library = "libEGL-not-here.so.1";
  for (RenderBackend b : {RenderBackend::kOsmesa, RenderBackend::kEgl, RenderBackend::kAuto}) {
    BackendChoice choice = ChooseRenderBackend(b, missing);
    EXPECT_EQ(choice.backend, RenderBackend::kCpu) << RenderBackendName(b);
    EXPECT_EQ(choice.context, nullptr);
    EXPECT_THAT(choice.reason, HasSubstr(b == RenderBackend::kOsmesa ? "libOSMesa-not-here" : "libEGL-not-here"));
  }
}

}  // namespace
}  // namespace px::render::gl
