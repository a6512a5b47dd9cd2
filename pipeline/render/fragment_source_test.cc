#include <gtest/gtest.h>

#include "pipeline/render/compositor.h"

namespace px::render {
namespace {

// A view of 8x6 whose one segment covers the whole image (its rectangle reaches one pixel centre
// past it on every side), drawn through the identity homography: novel pixel = source pixel.
struct WholeImageSegment {
  SceneView view;
  SegmentSetup setup;
  SceneSegment& segment() { return view.segments[0]; }

  WholeImageSegment() {
    view.camera.width = 8;
    view.camera.height = 6;
    view.texels.resize(static_cast<size_t>(view.camera.width + 2) * (view.camera.height + 2));
    view.segments.resize(1);
    segment().rect = {-1.0f, -1.0f, 8.0f, 6.0f};  // bbox (0, 0, 8, 6) grown by one pixel centre
    segment().drawn = true;
    setup.homography = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  }

  // FragmentSource at novel pixel (x, y).
  bool Source(float x, float y, float* u, float* v) const {
    SegmentRow r;
    r.y = static_cast<int>(y);
    r.hx0 = setup.homography[1] * y + setup.homography[2];
    r.hy0 = setup.homography[4] * y + setup.homography[5];
    r.hw0 = setup.homography[7] * y + setup.homography[8];
    return FragmentSource(setup, view.segments[0], r, x, u, v);
  }
};

// Every source point FragmentSource accepts is one the bilinear sampler can read: its 2x2 texel
// footprint lies inside the padded texel buffer, the far edges of the rectangle included (a
// segment touching the image's bottom edge seen exactly there read a row past the buffer).
TEST(FragmentSourceTest, AcceptedPointsKeepTheSamplersFootprintInTheTexels) {
  WholeImageSegment scene;
  const SegmentTexel* begin = scene.view.texels.data();
  const SegmentTexel* end = begin + scene.view.texels.size();
  int accepted = 0;
  for (float y = -1.5f; y <= 6.5f; y += 0.25f) {
    for (float x = -1.5f; x <= 8.5f; x += 0.25f) {
      float u = 0, v = 0;
      if (!scene.Source(x, y, &u, &v)) continue;
      ++accepted;
      const int iu = static_cast<int>(u + 1.0f) - 1, iv = static_cast<int>(v + 1.0f) - 1;
      const SegmentTexel* t00 = scene.view.TexelPtr(iu, iv);
      const SegmentTexel* t11 = t00 + scene.view.TexelStride() + 1;
      EXPECT_GE(t00, begin) << "at " << x << ", " << y;
      EXPECT_LT(t11, end) << "at " << x << ", " << y;
    }
  }
  EXPECT_GT(accepted, 30 * 30);
  float u = 0, v = 0;
  EXPECT_TRUE(scene.Source(7.75f, 5.75f, &u, &v));
  EXPECT_FALSE(scene.Source(8.0f, 3.0f, &u, &v)) << "the right edge of the rectangle";
  EXPECT_FALSE(scene.Source(3.0f, 6.0f, &u, &v)) << "the bottom edge of the rectangle";
  EXPECT_TRUE(scene.Source(-1.0f, -1.0f, &u, &v)) << "the top left corner of the rectangle";
}

// Behind the source camera (w <= 0) or not a number: no source point.
TEST(FragmentSourceTest, RefusesPointsBehindTheSourceCamera) {
  WholeImageSegment scene;
  scene.setup.homography = {1, 0, 0, 0, 1, 0, 0, 0, -1};
  float u = 0, v = 0;
  EXPECT_FALSE(scene.Source(2.0f, 2.0f, &u, &v));
  scene.setup.homography = {1, 0, 0, 0, 1, 0, 0, 0, 0};
  EXPECT_FALSE(scene.Source(2.0f, 2.0f, &u, &v));
}

}  // namespace
}  // namespace px::render
