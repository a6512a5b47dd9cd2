#include "pipeline/render/contradictions.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <numeric>
#include <opencv2/core.hpp>

namespace px::render {
namespace {

// What a view sees in front: per pixel the inverse depth of its layer-0 surface where that layer
// is solid (weight >= 1/2; 0 elsewhere: a soft edge or nothing, no say) and the surface's colour.
struct FrontSurface {
  int width = 0, height = 0;
  std::vector<float> inverse_depth;
  std::vector<std::array<uint8_t, 3>> colour;
};

FrontSurface FrontOf(const SceneView& view) {
  FrontSurface front;
  front.width = view.camera.width;
  front.height = view.camera.height;
  front.inverse_depth.assign(static_cast<size_t>(front.width) * front.height, 0.0f);
  front.colour.resize(front.inverse_depth.size());
  constexpr float kSolid = 0.5f * SegmentTexel::kWeightScale;
  for (int y = 0; y < front.height; ++y) {
    for (int x = 0; x < front.width; ++x) {
      const SegmentTexel& t = view.Texel(x, y);
      const size_t i = static_cast<size_t>(y) * front.width + x;
      if (t.segment[0] < 0 || t.weight[0] < kSolid) continue;
      const auto& p = view.segments[t.segment[0]].plane;
      const double inverse = p[0] * x + p[1] * y + p[2];
      if (!(inverse > 0)) continue;
      front.inverse_depth[i] = static_cast<float>(inverse);
      front.colour[i] = {t.colour[0][0], t.colour[0][1], t.colour[0][2]};
    }
  }
  return front;
}

int ColourDistance(const std::array<uint8_t, 4>& a, const std::array<uint8_t, 3>& b) {
  return std::max({std::abs(a[0] - b[0]), std::abs(a[1] - b[1]), std::abs(a[2] - b[2])});
}

// View `from`'s texel layers against view `by` (bit `bit`): sets the bit where `by` contradicts.
long MarkContradictions(const SceneView& from,
                        const SceneView& by,
                        const FrontSurface& front,
                        int bit,
                        const ConsistentBlendOptions& options,
                        std::vector<std::array<uint16_t, 2>>* masks) {
  const Rigid3 by_from_from = by.cam_from_world * from.cam_from_world.Inverse();
  const Eigen::Matrix3d r = by_from_from.RotationMatrix();
  const Eigen::Vector3d t = by_from_from.translation;
  const CameraModel& a = from.camera;
  const CameraModel& b = by.camera;
  // The free-space margin in inverse depth: free_space_px of disparity between the two views.
  const double baseline = t.norm();
  if (!(baseline > 0)) return 0;
  const float margin = static_cast<float>(options.free_space_px / (std::min(b.fx, b.fy) * baseline));
  const uint16_t flag = static_cast<uint16_t>(1u << bit);
  std::atomic<long> marked{0};
  cv::parallel_for_(cv::Range(0, a.height), [&](const cv::Range& rows) {
    long count = 0;
    for (int y = rows.start; y < rows.end; ++y) {
      for (int x = 0; x < a.width; ++x) {
        const SegmentTexel& texel = from.Texel(x, y);
        for (int layer = 0; layer < 2; ++layer) {
          const int32_t s = texel.segment[layer];
          if (s < 0 || texel.weight[layer] <= 0) continue;
          const auto& p = from.segments[s].plane;
          const double inverse = p[0] * x + p[1] * y + p[2];
          if (!(inverse > 0)) continue;
          const double z = 1.0 / inverse;
          const Eigen::Vector3d point = r * Eigen::Vector3d(z * (x - a.cx) / a.fx, z * (y - a.cy) / a.fy, z) + t;
          if (!(point.z() > 0)) continue;
          const double u = b.fx * point.x() / point.z() + b.cx, v = b.fy * point.y() / point.z() + b.cy;
          if (!(u >= 0 && v >= 0 && u <= b.width - 1 && v <= b.height - 1)) continue;
          // The footprint of the point in `by`: every pixel must see free space behind a colour of
          // its own; one that sees the surface (or something nearer), or nothing solid, has a say.
          const int u0 = std::min(static_cast<int>(u), b.width - 2), v0 = std::min(static_cast<int>(v), b.height - 2);
          const float point_inverse = static_cast<float>(1.0 / point.z());
          bool contradicted = true;
          for (int k = 0; k < 4 && contradicted; ++k) {
            const size_t i = static_cast<size_t>(v0 + (k >> 1)) * front.width + (u0 + (k & 1));
            const float seen = front.inverse_depth[i];
            contradicted = seen > 0 && point_inverse - seen > margin &&
                           ColourDistance(texel.colour[layer], front.colour[i]) > options.colour_levels;
          }
          if (!contradicted) continue;
          (*masks)[static_cast<size_t>(y + 1) * from.TexelStride() + (x + 1)][layer] |= flag;
          ++count;
        }
      }
    }
    marked += count;
  });
  return marked;
}

}  // namespace

long FindContradictions(const ConsistentBlendOptions& options,
                        const std::vector<std::vector<int>>& slot_neighbours,
                        std::vector<SceneView>* views) {
  const int n = static_cast<int>(views->size());
  std::vector<FrontSurface> fronts;
  fronts.reserve(views->size());
  for (const SceneView& view : *views) fronts.push_back(FrontOf(view));
  long total = 0;
  for (int i = 0; i < n; ++i) {
    SceneView& view = (*views)[i];
    view.neighbour_bit.fill(-1);
    view.neighbours.clear();
    view.contradicted.clear();
    const Eigen::Vector3d centre = CameraCentre(view.cam_from_world);
    std::vector<int> others = i < static_cast<int>(slot_neighbours.size()) ? slot_neighbours[i] : std::vector<int>();
    std::sort(others.begin(), others.end(), [&](int a, int b) {
      return (CameraCentre((*views)[a].cam_from_world) - centre).norm() <
             (CameraCentre((*views)[b].cam_from_world) - centre).norm();
    });
    if (static_cast<int>(others.size()) > options.max_neighbours) others.resize(options.max_neighbours);
    std::vector<std::array<uint16_t, 2>> masks(view.texels.size(), {0, 0});
    long marked = 0;
    for (size_t bit = 0; bit < others.size(); ++bit) {
      view.neighbours.push_back(others[bit]);
      view.neighbour_bit[others[bit]] = static_cast<int8_t>(bit);
      marked +=
          MarkContradictions(view, (*views)[others[bit]], fronts[others[bit]], static_cast<int>(bit), options, &masks);
    }
    if (marked > 0) {
      for (int y = 0; y < view.camera.height; ++y) {
        for (int x = 0; x < view.camera.width; ++x) {
          const size_t index = static_cast<size_t>(y + 1) * view.TexelStride() + (x + 1);
          const SegmentTexel& t = view.texels[index];
          for (int layer = 0; layer < 2; ++layer) {
            if (masks[index][layer] != 0) view.segments[t.segment[layer]].contradicted = true;
          }
        }
      }
      view.contradicted = std::move(masks);
    }
    total += marked;
  }
  return total;
}

}  // namespace px::render
