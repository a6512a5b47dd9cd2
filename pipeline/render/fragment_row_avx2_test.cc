#include "pipeline/render/fragment_row_avx2.h"

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "pipeline/render/compositor.h"
#include "pipeline/render/cpu_scene_renderer.h"
#include "pipeline/render/render_test_util.h"

namespace px::render {
namespace {

// True when the two images have the same size, type and bytes (NaNs and signed zeros included).
bool SameBits(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size() || a.type() != b.type()) return false;
  const size_t row_bytes = a.cols * a.elemSize();
  for (int y = 0; y < a.rows; ++y) {
    if (std::memcmp(a.ptr(y), b.ptr(y), row_bytes) != 0) return false;
  }
  return true;
}

Rigid3 PoseAt(const Eigen::Vector3d& centre, double yaw_deg, double pitch_deg) {
  const Eigen::Quaterniond rotation(Eigen::AngleAxisd(yaw_deg * M_PI / 180, Eigen::Vector3d::UnitY()) *
                                    Eigen::AngleAxisd(pitch_deg * M_PI / 180, Eigen::Vector3d::UnitX()));
  return Rigid3(rotation, -(rotation * centre));
}

// Novel cameras that exercise the row kernel's cases: between the lenses, the dolly in front of
// the rig, beyond the lattice (holes, views behind), turned and zoomed (slanted rows, partial
// blocks of eight), and an odd output size (rows that end mid-block).
struct NovelCamera {
  std::string name;
  CameraModel camera;
  Rigid3 cam_from_world;
};
std::vector<NovelCamera> NovelCameras(const CameraModel& source) {
  CameraModel zoomed = source;
  zoomed.fx = zoomed.fy = 1.3 * source.fx;
  CameraModel odd = CameraModel::Pinhole(source.width - 3, source.height - 1, source.fx);
  return {
      {"between lenses", source, PoseAt({0.011, 0.006, 0.0}, 1, 0)},
      {"dolly in", source, PoseAt({-0.004, 0.004, 0.02}, 0, 0)},
      {"beyond the lattice", source, PoseAt({0.06, -0.03, -0.01}, -3, 2)},
      {"turned and zoomed", zoomed, PoseAt({0.0, 0.01, 0.01}, 4, -3)},
      {"odd size", odd, PoseAt({0.007, -0.009, 0.0}, 0.5, 0.5)},
  };
}

class FragmentRowAvx2Test : public ::testing::TestWithParam<int> {
 protected:
  void SetUp() override {
    if (!CpuHasAvx2()) GTEST_SKIP() << "this CPU has no AVX2: only the scalar path runs here";
    const int views = GetParam();
    const int rows = views == 9 ? 3 : 4, cols = views == 9 ? 3 : 5;
    testing::MakeLayeredLattice(testing::PlaneScene{}, rows, cols, views == 9 ? 0.025 : 0.0125, kCamera, &views_,
                                &layers_);
  }

  const CameraModel kCamera = CameraModel::Pinhole(320, 240, 280);
  std::vector<View> views_;
  std::vector<LayeredDepthView> layers_;
};

// The composite itself (before hole filling), float for float: colour, alpha, depth and the
// fragment count, with and without colour (Render() and Coverage()).
TEST_P(FragmentRowAvx2Test, CompositeIsTheScalarPathsBitForBit) {
  auto scene = LayeredScene::Create(views_, layers_, RenderOptions{});
  ASSERT_TRUE(scene.ok()) << scene.status().ToString();
  for (const NovelCamera& novel : NovelCameras(kCamera)) {
    std::vector<ViewSlots> slots;
    scene->mesh().ComputeWeights(novel.camera, novel.cam_from_world, &slots);
    std::vector<FrameView> frame_views;
    SetUpFrame(*scene, novel.camera, novel.cam_from_world, slots, &frame_views);
    for (bool with_colour : {true, false}) {
      SCOPED_TRACE(novel.name + (with_colour ? ", colour" : ", coverage only"));
      FrameComposite scalar, avx2;
      CompositePreview(*scene, frame_views, slots, novel.camera.width, novel.camera.height, with_colour, &scalar,
                       FragmentPath::kScalar);
      CompositePreview(*scene, frame_views, slots, novel.camera.width, novel.camera.height, with_colour, &avx2,
                       FragmentPath::kAvx2);
      EXPECT_GT(scalar.fragments, novel.camera.width * novel.camera.height / 2);
      EXPECT_EQ(avx2.fragments, scalar.fragments);
      EXPECT_TRUE(SameBits(avx2.alpha, scalar.alpha));
      EXPECT_TRUE(SameBits(avx2.depth, scalar.depth));
      EXPECT_TRUE(SameBits(avx2.colour, scalar.colour));
    }
  }
}

// The whole frame through the renderer (holes drawn from other views and filled), with the
// option that forces the scalar path.
TEST_P(FragmentRowAvx2Test, RendererFramesAreTheScalarPathsBitForBit) {
  RenderOptions scalar_options;
  scalar_options.avx2_fragments = false;
  auto scalar = CpuSceneRenderer::Create(views_, layers_, scalar_options);
  auto avx2 = CpuSceneRenderer::Create(views_, layers_, RenderOptions{});
  ASSERT_TRUE(scalar.ok() && avx2.ok());
  for (const NovelCamera& novel : NovelCameras(kCamera)) {
    SCOPED_TRACE(novel.name);
    VirtualCamera request;
    request.camera = novel.camera;
    request.cam_from_world = novel.cam_from_world;
    auto a = (*scalar)->Render(request);
    auto b = (*avx2)->Render(request);
    ASSERT_TRUE(a.ok() && b.ok());
    EXPECT_TRUE(SameBits(b->bgr, a->bgr));
    EXPECT_TRUE(SameBits(b->depth_m, a->depth_m));
    EXPECT_TRUE(SameBits(b->coverage, a->coverage));
    EXPECT_EQ((*avx2)->last_frame().fragments, (*scalar)->last_frame().fragments);
  }
}

INSTANTIATE_TEST_SUITE_P(Lattices, FragmentRowAvx2Test, ::testing::Values(9, 20),
                         [](const ::testing::TestParamInfo<int>& p) { return std::to_string(p.param) + "views"; });

}  // namespace
}  // namespace px::render
