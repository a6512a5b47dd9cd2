// One captured scene prepared for rendering (ALGORITHM.md sections 1 and 2): every view's segment
// images packed into texels, each segment's rectangle lifted onto its plane in world coordinates,
// the view mesh over the views, and the soft z-buffer's depth range. Built once per shot and
// shared by every frame and by every back end's CPU-side setup.
//
// Bad content is sanitised, not fatal: segments with non-finite planes or planes behind infinity
// at their centre, and texels with bad weights or segment indices, count as uncovered; a plane
// that passes infinity only within its rectangle is drawn facing the camera at its centre's depth; a view left without
// any segment gets no view-mesh vertex. Each such repair is named in warnings().
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "pipeline/core/camera_model.h"
#include "pipeline/core/layered_depth.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/status.h"
#include "pipeline/core/view.h"
#include "pipeline/render/render_options.h"
#include "pipeline/render/soft_z.h"
#include "pipeline/render/view_mesh.h"

namespace px::render {

// Both segment layers of one source pixel (ALGORITHM.md section 1: the CPU texel), 24 bytes.
struct SegmentTexel {
  static constexpr float kWeightScale = 65535.0f;
  std::array<int32_t, 2> segment = {SegmentLayer::kNoSegment, SegmentLayer::kNoSegment};
  // Layer weight quantised to 1/kWeightScale, stored as that integer in a float: the fetch
  // needs no conversion and gives the same products as the 16-bit integer did.
  std::array<float, 2> weight = {0, 0};
  // B, G, R and a constant 1 per layer: one 4-lane load per layer, the 1 carries the layer's
  // weight into the sample's alpha lane (segment_raster.h).
  std::array<std::array<uint8_t, 4>, 2> colour{};
};
static_assert(sizeof(SegmentTexel) == 24, "three texels per 72 bytes; the sampler reads 4 colour bytes per layer");

// A segment drawn as the rectangle of its bbox grown by one pixel centre, on its plane.
struct SceneSegment {
  std::array<float, 4> rect{};                      // u_min, v_min, u_max, v_max in source pixels
  std::array<double, 3> plane{};                    // inverse depth a, b, c: 1/z = a u + b v + c
  std::array<Eigen::Vector3d, 4> corners_in_world;  // (u_min,v_min), (u_max,v_min), (u_max,v_max), (u_min,v_max)
  Eigen::Vector3d centre_in_world = Eigen::Vector3d::Zero();  // the bbox centre on the plane
  bool drawn = false;                                         // false: dropped (bad plane) or covering no pixel
  bool contradicted = false;                                  // some texel of it is (SceneView::contradicted)
};

struct SceneView {
  ViewId id;
  CameraModel camera;
  Rigid3 cam_from_world;
  // Row-major with an empty border of one texel on every side (so that a bilinear footprint
  // reaching one pixel past the image needs no bounds checks): (width + 2) x (height + 2).
  std::vector<SegmentTexel> texels;
  std::vector<SceneSegment> segments;  // index = the LayeredDepthView's segment index
  // Contradictions (contradictions.h), in the layout of `texels`: bit j of contradicted[i][layer]
  // is set when the view neighbours[j] (an index in LayeredScene::views()) sees free space of
  // another colour where that layer's surface lies. Empty when nothing is contradicted.
  std::vector<std::array<uint16_t, 2>> contradicted;
  std::vector<int> neighbours;
  std::array<int8_t, 256> neighbour_bit;  // scene view index -> bit in `contradicted`, or -1

  int TexelStride() const { return camera.width + 2; }
  // Pixel (x, y), for -1 <= x <= width and -1 <= y <= height.
  const SegmentTexel* TexelPtr(int x, int y) const {
    return texels.data() + static_cast<ptrdiff_t>(y + 1) * TexelStride() + (x + 1);
  }
  const SegmentTexel& Texel(int x, int y) const { return *TexelPtr(x, y); }
  // The views contradicting segment `segment` at source pixel (u, v) (within one pixel of the
  // image): the mask of the nearest texel's layer that holds the segment, 0 when neither does.
  uint16_t ContradictedAt(int32_t segment, float u, float v) const {
    const int iu = static_cast<int>(u + 1.5f) - 1, iv = static_cast<int>(v + 1.5f) - 1;
    const size_t index = static_cast<size_t>(iv + 1) * TexelStride() + (iu + 1);
    const SegmentTexel& t = texels[index];
    return t.segment[0] == segment ? contradicted[index][0] : t.segment[1] == segment ? contradicted[index][1] : 0;
  }
};

class LayeredScene {
 public:
  // views[i] gives the pose of the layered view with the same id (its image is not used). Every
  // layered view needs a view; sizes and types must match its camera (errors name the view and
  // the image); cameras must be undistorted pinholes.
  static StatusOr<LayeredScene> Create(const std::vector<View>& views,
                                       const std::vector<LayeredDepthView>& layers,
                                       const RenderOptions& options);

  // The views that take part (those with at least one drawable segment); the mesh's view index
  // is the position here.
  const std::vector<SceneView>& views() const { return views_; }
  const ViewMesh& mesh() const { return mesh_; }
  const SoftZ& soft_z() const { return soft_z_; }
  double depth_range_m() const { return soft_z_.rho(); }
  // The 1st and 99th percentiles of the views' front-layer depths (metres, in each view's camera).
  double near_m() const { return near_m_; }
  double far_m() const { return far_m_; }
  // Repairs and exclusions, one line each ("view 3: 12 segments dropped: plane not finite").
  const std::vector<std::string>& warnings() const { return warnings_; }
  // Texel layers some neighbouring view contradicts (contradictions.h); 0 when not looked for.
  long contradicted_texels() const { return contradicted_texels_; }

 private:
  std::vector<SceneView> views_;
  ViewMesh mesh_;
  SoftZ soft_z_;
  double near_m_ = 1.0;
  double far_m_ = 1.0;
  long contradicted_texels_ = 0;
  std::vector<std::string> warnings_;
};

}  // namespace px::render
