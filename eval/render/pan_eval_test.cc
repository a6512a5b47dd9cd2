#include "eval/render/pan_eval.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "sim/synthetic/data_paths.h"

namespace px::eval {
namespace {

// The pan at a quarter of the size (160x120) with exact depth: the frames score as the standard
// group's viewpoints do, and the frame-to-frame changes follow the truth's closely.
TEST(PanEvalTest, StillLifeAtQuarterSizeWithExactDepth) {
  RenderEvalOptions options;
  options.sim_scale = 0.25;
  options.depths = {EvalDepth::kTruth};
  StatusOr<std::vector<RenderEvalCase>> cases =
      EvaluateSimulatedPan(sim::ScenesDir() / "still_life.json", SimCameraSpec::Pop9(), options);
  ASSERT_TRUE(cases.ok()) << cases.status().ToString();
  ASSERT_EQ(cases->size(), 1u);
  const RenderEvalCase& c = cases->front();
  std::printf("%s, %s: %dx%d PSNR %.2f dB (mean of frames), temporal %.2f dB\n",
              c.dataset.c_str(),
              c.viewpoint.c_str(),
              c.width,
              c.height,
              c.psnr_db,
              c.temporal_psnr_db);
  EXPECT_EQ(c.dataset, "sim still_life 3x3 pan");
  EXPECT_EQ(c.viewpoint, "on the lattice plane, 16 frames");
  EXPECT_EQ(c.width, 160);
  EXPECT_GT(c.psnr_db, 28.0);
  // The changes between frames are what the truth's are, up to errors that come and go: far above
  // the frames' own PSNR, as the errors a frame shares with the next do not count.
  EXPECT_GT(c.temporal_psnr_db, c.psnr_db + 2.0);
  EXPECT_LT(c.temporal_psnr_db, 99.0);
}

}  // namespace
}  // namespace px::eval
