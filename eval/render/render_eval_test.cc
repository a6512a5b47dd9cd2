#include "eval/render/render_eval.h"

#include <cstdio>
#include <filesystem>

#include <gtest/gtest.h>

#include "sim/synthetic/data_paths.h"

namespace px::eval {
namespace {

// The evaluation on a small subset: one scene on the Pop9 lattice at a quarter of the tile size
// (160x120). The full table (640x480, more scenes, HCI and fern) is `parallax eval render`.
TEST(RenderEvalTest, SimulatedSceneAtQuarterSize) {
  RenderEvalOptions options;
  options.sim_scale = 0.25;
  StatusOr<std::vector<RenderEvalCase>> cases =
      EvaluateSimulatedScene(sim::ScenesDir() / "still_life.json", SimCameraSpec::Pop9(), options);
  ASSERT_TRUE(cases.ok()) << cases.status().ToString();
  ASSERT_EQ(cases->size(), 4u);
  for (const RenderEvalCase& c : *cases) {
    std::printf("%s, %s: %dx%d PSNR %.2f dB SSIM %.4f holes %.4f\n", c.dataset.c_str(), c.viewpoint.c_str(), c.width,
                c.height, c.psnr_db, c.ssim, c.hole_ratio);
    EXPECT_EQ(c.width, 160);
    EXPECT_EQ(c.num_sources, 9);
    // Exact depth, sources all around: far above what a renderer ignoring depth scores (about
    // 20 dB); the bound leaves room for the quarter size's coarser sampling at edges.
    EXPECT_GT(c.psnr_db, 28.0) << c.viewpoint;
    EXPECT_GT(c.ssim, 0.85) << c.viewpoint;
    EXPECT_LT(c.hole_ratio, 0.1) << c.viewpoint;
  }
}

TEST(RenderEvalTest, MissingDatasetsAreErrorsThatNameThem) {
  const StatusOr<std::vector<RenderEvalCase>> hci = EvaluateHciCentreView("/nonexistent/hci", RenderEvalOptions());
  ASSERT_FALSE(hci.ok());
  EXPECT_NE(hci.status().message().find("/nonexistent/hci"), std::string::npos) << hci.status().ToString();
  const StatusOr<std::vector<RenderEvalCase>> llff = EvaluateLlffHeldOut("/nonexistent/fern", RenderEvalOptions());
  ASSERT_FALSE(llff.ok());
  EXPECT_NE(llff.status().message().find("/nonexistent/fern"), std::string::npos) << llff.status().ToString();
  RenderEvalOptions bad;
  bad.sim_scale = 0;
  EXPECT_NE(bad.Validate().message().find("sim_scale"), std::string::npos);
}

}  // namespace
}  // namespace px::eval
