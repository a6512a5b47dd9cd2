// Our depth stage on real benchmark data: the HCI antinous light field's central 3x3 views,
// cropped to the middle 192x192 to keep the test quick, scored with the benchmark's BadPix 0.07.
// Skips without ../shared/data.
#include "eval/depth/depth_eval.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <vector>

#include "eval/datasets/hci_light_field.h"
#include "eval/depth/depth_metrics.h"
#include "pipeline/depth/depth_stage.h"
#include "sim/synthetic/data_paths.h"

namespace px::eval {
namespace {

TEST(DepthEvalHciTest, CentralThreeByThreeCropBadPix007) {
  const std::filesystem::path dir = sim::SharedDataDir() / "hci_4dlf_antinous";
  if (!std::filesystem::exists(dir / "parameters.cfg")) {
    GTEST_SKIP() << "HCI antinous light field not found in " << dir;
  }
  StatusOr<HciLightField> lf = LoadHciLightField(dir);
  ASSERT_TRUE(lf.ok()) << lf.status().ToString();
  const cv::Rect crop(160, 160, 192, 192);
  std::vector<View> views = lf->CentreGrid(1);
  for (View& view : views) {
    view.image = view.image(crop).clone();
    view.camera.width = crop.width;
    view.camera.height = crop.height;
    view.camera.cx -= crop.x;
    view.camera.cy -= crop.y;
  }
  DepthOptions options = LightFieldDepthOptions(DepthOptions());
  options.min_depth_m = lf->DepthFromDisparity(lf->disp_max);
  options.max_depth_m = lf->DepthFromDisparity(lf->disp_min);
  StatusOr<DepthStageResult> result = ComputeLayeredDepthForViews(views, {4}, options);
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  ASSERT_TRUE(ValidateLayeredDepthView(result->layered[0]).ok());
  cv::Mat disparity(crop.size(), CV_32F);
  for (int y = 0; y < crop.height; ++y) {
    for (int x = 0; x < crop.width; ++x) {
      disparity.at<float>(y, x) = static_cast<float>(lf->DisparityFromDepth(result->maps[0].depth_m.at<float>(y, x)));
    }
  }
  const HciMetrics metrics = EvaluateHciDisparity(disparity, lf->gt_disparity(crop).clone());
  std::printf("HCI antinous 3x3, 192x192 crop: BadPix.07 %.2f %%, BadPix.03 %.2f %%, MSE x 100 %.3f\n",
              metrics.bad_pix_007,
              metrics.bad_pix_003,
              metrics.mse_x100);
  // About 16 % on this crop with the light-field options (the whole view scores under 15 %; the
  // naive plane sweep 37.6 %): the bound leaves a few points for platform differences in the
  // SLIC segmentation.
  EXPECT_LT(metrics.bad_pix_007, 20.0);
}

}  // namespace
}  // namespace px::eval
