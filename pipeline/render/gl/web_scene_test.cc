#include "pipeline/render/gl/web_scene.h"

#include <gtest/gtest.h>

#include <cstring>
#include <nlohmann/json.hpp>

#include "pipeline/render/gl/layered_plane_scene_testing.h"
#include "pipeline/render/gl/view_texels.h"

namespace px::render::gl {
namespace {

std::vector<PosedLayeredView> TwoByTwoScene() {
  return testing::LayeredPlaneScene(render::testing::PlaneScene{}, 2, 2, 0.025, CameraModel::Pinhole(64, 48, 56), 16);
}

TEST(WebSceneTest, HoldsWhatTheGlBackEndUploads) {
  const std::vector<PosedLayeredView> views = TwoByTwoScene();
  const GlSceneRendererOptions options;
  StatusOr<std::string> scene = ExportWebScene(views, options);
  ASSERT_TRUE(scene.ok()) << scene.status().message();
  ASSERT_GE(scene->size(), 16u);
  uint32_t prefix[4];
  std::memcpy(prefix, scene->data(), sizeof(prefix));
  EXPECT_EQ(std::string(scene->data(), 4), "PXWS");
  EXPECT_EQ(prefix[1], static_cast<uint32_t>(kWebSceneVersion));
  EXPECT_EQ(prefix[2] % 8, 0u);
  const nlohmann::json header = nlohmann::json::parse(scene->substr(16, prefix[2]));
  ASSERT_EQ(header["views"].size(), views.size());
  EXPECT_GT(header["rho_m"].get<double>(), 0);
  EXPECT_EQ(header["mesh"]["triangles"].get<int>() * 3 + header["mesh"]["edges"].get<int>() * 2,
            static_cast<int>(header["mesh"]["uniforms"].size()));
  // What GlSceneRenderer::Upload uploads.
  std::vector<PosedLayeredView> uploaded = views;
  StatusOr<PreparedScene> prepared = PrepareScene(&uploaded, options.seam_skirts);
  ASSERT_TRUE(prepared.ok()) << prepared.status().message();
  const std::vector<std::array<float, 4>> uniforms = MeshUniforms(prepared->mesh);
  ASSERT_EQ(header["mesh"]["uniforms"].size(), uniforms.size());
  for (size_t u = 0; u < uniforms.size(); ++u) {
    for (int c = 0; c < 4; ++c) EXPECT_EQ(header["mesh"]["uniforms"][u][c].get<float>(), uniforms[u][c]);
  }
  EXPECT_DOUBLE_EQ(header["rho_m"].get<double>(), prepared->rho_m);

  size_t end = 16 + prefix[2];
  for (size_t v = 0; v < views.size(); ++v) {
    const nlohmann::json& view = header["views"][v];
    const ViewTexels& expected = prepared->texels[v];
    ASSERT_EQ(view["texels_offset"].get<size_t>(), end) << "blocks follow each other, view " << v;
    ASSERT_EQ(view["segments"].get<size_t>(), expected.kept_segments.size());
    const size_t texel_bytes = expected.texels.total() * 16;
    EXPECT_EQ(std::memcmp(scene->data() + end, expected.texels.data, texel_bytes), 0) << "view " << v << "'s texels";
    const size_t segments_offset = view["segments_offset"].get<size_t>();
    EXPECT_EQ(segments_offset % 8, 0u);
    double first[8];
    std::memcpy(first, scene->data() + segments_offset, sizeof(first));
    const DepthSegment& segment = views[v].depth.segments[expected.kept_segments[0]];
    EXPECT_EQ(first[0], segment.bbox.x);
    EXPECT_EQ(first[6], segment.inv_depth_c);
    EXPECT_EQ(first[7], expected.kept_segments[0]);
    EXPECT_DOUBLE_EQ(view["fx"].get<double>(), 56);
    end = segments_offset + expected.kept_segments.size() * 8 * sizeof(double);
  }
  EXPECT_EQ(end, scene->size());
}

TEST(WebSceneTest, RefusesViewsItCannotDraw) {
  std::vector<PosedLayeredView> views = TwoByTwoScene();
  views[1].depth.layers[0].weight = cv::Mat(3, 3, CV_32F, cv::Scalar(1));
  StatusOr<std::string> scene = ExportWebScene(views, GlSceneRendererOptions{});
  ASSERT_FALSE(scene.ok());
  EXPECT_NE(scene.status().message().find("view 1"), std::string::npos) << scene.status().message();
  EXPECT_FALSE(ExportWebScene({}, GlSceneRendererOptions{}).ok());
}

}  // namespace
}  // namespace px::render::gl
