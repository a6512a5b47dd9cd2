#include "pipeline/render/layered_scene.h"

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <string>

#include "pipeline/render/bilinear_prefilter.h"
#include "pipeline/render/contradictions.h"
#include "pipeline/render/seam_skirts.h"

namespace px::render {
namespace {

// A rectangle corner whose inverse depth is below this (1/m) lies at or behind infinity.
constexpr double kMinInverseDepth = 1e-6;

std::string ViewName(ViewId id) { return "view " + std::to_string(id.value); }

Status CheckImage(const cv::Mat& image, int type, const CameraModel& camera, const std::string& what) {
  if (image.type() != type || image.cols != camera.width || image.rows != camera.height) {
    return InvalidArgumentError(what + " is " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                                " of type " + std::to_string(image.type()) + ", want " + std::to_string(camera.width) +
                                "x" + std::to_string(camera.height) + " of type " + std::to_string(type));
  }
  return OkStatus();
}

// The 3D point (world) of source pixel (u, v) on a segment's plane.
Eigen::Vector3d Lift(const SceneView& view, const std::array<double, 3>& plane, double u, double v) {
  const double z = 1.0 / (plane[0] * u + plane[1] * v + plane[2]);
  const Eigen::Vector3d p_in_cam(
      z * (u - view.camera.cx) / view.camera.fx, z * (v - view.camera.cy) / view.camera.fy, z);
  return view.cam_from_world.rotation.conjugate() * (p_in_cam - view.cam_from_world.translation);
}

// Packs one view's layers into texels and its segments into rectangles; counts what it drops.
SceneView PrepareView(const View& pose, const LayeredDepthView& layered, std::vector<std::string>* warnings) {
  SceneView view;
  view.id = layered.id;
  view.camera = layered.camera;
  view.cam_from_world = pose.cam_from_world;
  const int width = layered.camera.width, height = layered.camera.height;
  const int num_segments = layered.NumSegments();
  view.segments.resize(num_segments);
  int bad_plane = 0, behind_infinity = 0, flattened = 0;
  for (int s = 0; s < num_segments; ++s) {
    const DepthSegment& segment = layered.segments[s];
    SceneSegment& out = view.segments[s];
    out.plane = {segment.inv_depth_a, segment.inv_depth_b, segment.inv_depth_c};
    const cv::Rect& b = segment.bbox;
    if (!std::isfinite(out.plane[0]) || !std::isfinite(out.plane[1]) || !std::isfinite(out.plane[2]) || b.width <= 0 ||
        b.height <= 0 || (b & cv::Rect(0, 0, width, height)) != b) {
      ++bad_plane;
      continue;
    }
    out.rect = {static_cast<float>(b.x - 1),
                static_cast<float>(b.y - 1),
                static_cast<float>(b.x + b.width),
                static_cast<float>(b.y + b.height)};
    const std::array<std::array<double, 2>, 4> corners = {{{out.rect[0], out.rect[1]},
                                                           {out.rect[2], out.rect[1]},
                                                           {out.rect[2], out.rect[3]},
                                                           {out.rect[0], out.rect[3]}}};
    bool positive = true;
    for (const auto& c : corners) {
      positive = positive && out.plane[0] * c[0] + out.plane[1] * c[1] + out.plane[2] > kMinInverseDepth;
    }
    if (!positive) {
      // A far plane steep enough to pass infinity within its rectangle (sky, distant ground):
      // its texels are still seen, so it is drawn facing the camera at its centre's depth.
      const double centre =
          out.plane[0] * (b.x + 0.5 * (b.width - 1)) + out.plane[1] * (b.y + 0.5 * (b.height - 1)) + out.plane[2];
      if (!(centre > kMinInverseDepth)) {
        ++behind_infinity;
        continue;
      }
      out.plane = {0.0, 0.0, centre};
      ++flattened;
    }
    for (int k = 0; k < 4; ++k) out.corners_in_world[k] = Lift(view, out.plane, corners[k][0], corners[k][1]);
    out.centre_in_world = Lift(view, out.plane, b.x + 0.5 * (b.width - 1), b.y + 0.5 * (b.height - 1));
    out.drawn = true;
  }

  view.texels.resize(static_cast<size_t>(width + 2) * (height + 2));
  std::vector<int> used(num_segments, 0);
  int bad_texels = 0;
  const std::array<cv::Mat, 2> colours = PrefilterForBilinear(layered);
  for (int y = 0; y < height; ++y) {
    SegmentTexel* row = view.texels.data() + static_cast<size_t>(y + 1) * view.TexelStride() + 1;
    for (int layer = 0; layer < 2; ++layer) {
      const SegmentLayer& l = layered.layers[layer];
      const cv::Vec3b* colour = colours[layer].ptr<cv::Vec3b>(y);
      const float* weight = l.weight.ptr<float>(y);
      const int32_t* segment = l.segment.ptr<int32_t>(y);
      for (int x = 0; x < width; ++x) {
        const float w = weight[x];
        const int32_t s = segment[x];
        if (!(w > 0)) continue;  // 0, negative or NaN: nothing there
        if (!(w <= 1.0f) || s < 0 || s >= num_segments || !view.segments[s].drawn ||
            !layered.segments[s].bbox.contains(cv::Point(x, y))) {
          ++bad_texels;
          continue;
        }
        SegmentTexel& t = row[x];
        t.segment[layer] = s;
        t.weight[layer] = static_cast<float>(std::lround(w * SegmentTexel::kWeightScale));
        t.colour[layer] = {colour[x][0], colour[x][1], colour[x][2], 1};
        used[s] = 1;
      }
    }
  }
  int unused = 0;
  for (int s = 0; s < num_segments; ++s) {
    if (view.segments[s].drawn && !used[s]) {
      view.segments[s].drawn = false;  // covers no pixel: nothing to draw
      ++unused;
    }
  }
  (void)unused;
  const std::string name = ViewName(view.id);
  if (bad_plane > 0) {
    warnings->push_back(name + ": " + std::to_string(bad_plane) +
                        " segments dropped: plane not finite or bbox outside the view");
  }
  if (behind_infinity > 0) {
    warnings->push_back(name + ": " + std::to_string(behind_infinity) +
                        " segments dropped: plane at or behind infinity at the rectangle's centre");
  }
  if (flattened > 0) {
    warnings->push_back(name + ": " + std::to_string(flattened) +
                        " segments drawn facing the camera at their centre's depth: plane at or behind infinity at a "
                        "rectangle corner");
  }
  if (bad_texels > 0) {
    warnings->push_back(name + ": " + std::to_string(bad_texels) +
                        " layer texels ignored: weight above 1, or segment index invalid, dropped or outside its bbox");
  }
  return view;
}

struct DepthPercentiles {
  double near_m = 0;  // 1st percentile
  double median_m = 0;
  double far_m = 0;  // 99th percentile
};

// The 1st, 50th and 99th percentiles of the layer-0 depths of every view (every 4th pixel); all 1 m
// when no view has depth.
DepthPercentiles SceneDepthPercentiles(const std::vector<SceneView>& views) {
  std::vector<float> depths;
  for (const SceneView& view : views) {
    for (int y = 0; y < view.camera.height; y += 4) {
      for (int x = 0; x < view.camera.width; x += 4) {
        const SegmentTexel& t = view.Texel(x, y);
        if (t.weight[0] == 0) continue;
        const auto& p = view.segments[t.segment[0]].plane;
        const double inv = p[0] * x + p[1] * y + p[2];
        if (inv > 0) depths.push_back(static_cast<float>(1.0 / inv));
      }
    }
  }
  if (depths.empty()) return {1.0, 1.0, 1.0};
  const auto at = [&](double q) {
    auto it = depths.begin() + static_cast<std::ptrdiff_t>(q * static_cast<double>(depths.size() - 1));
    std::nth_element(depths.begin(), it, depths.end());
    return static_cast<double>(*it);
  };
  return {at(0.01), at(0.5), at(0.99)};
}

}  // namespace

StatusOr<LayeredScene> LayeredScene::Create(const std::vector<View>& views,
                                            const std::vector<LayeredDepthView>& layers,
                                            const RenderOptions& options) {
  PX_RETURN_IF_ERROR(options.Validate());
  if (layers.empty()) return InvalidArgumentError("render: no layered depth views");
  LayeredScene scene;
  for (size_t i = 0; i < layers.size(); ++i) {
    const LayeredDepthView& layered = layers[i];
    const std::string name = "render: " + ViewName(layered.id);
    for (size_t j = 0; j < i; ++j) {
      if (layers[j].id == layered.id) return InvalidArgumentError(name + ": appears twice");
    }
    const auto pose = std::find_if(views.begin(), views.end(), [&](const View& v) { return v.id == layered.id; });
    if (pose == views.end()) return InvalidArgumentError(name + ": no view (pose) with this id");
    PX_RETURN_IF_ERROR(layered.camera.Validate().WithContext(name));
    if (layered.camera.HasDistortion()) {
      return InvalidArgumentError(name + ": camera has lens distortion; the renderer needs undistorted views");
    }
    if (!pose->cam_from_world.rotation.coeffs().allFinite() || !pose->cam_from_world.translation.allFinite()) {
      return InvalidArgumentError(name + ": pose is not finite");
    }
    if (layered.NumSegments() > (1 << 30)) return InvalidArgumentError(name + ": too many segments");
    for (int layer = 0; layer < 2; ++layer) {
      const SegmentLayer& l = layered.layers[layer];
      const std::string what = name + " layer " + std::to_string(layer);
      PX_RETURN_IF_ERROR(CheckImage(l.colour, CV_8UC3, layered.camera, what + " colour"));
      PX_RETURN_IF_ERROR(CheckImage(l.weight, CV_32F, layered.camera, what + " weight"));
      PX_RETURN_IF_ERROR(CheckImage(l.segment, CV_32S, layered.camera, what + " segment"));
    }
    SceneView view = PrepareView(*pose, WithSeamSkirts(layered, options.seam_skirts), &scene.warnings_);
    const bool any =
        std::any_of(view.segments.begin(), view.segments.end(), [](const SceneSegment& s) { return s.drawn; });
    if (!any) {
      scene.warnings_.push_back(ViewName(layered.id) + " has no valid depth (no drawable segment): left out");
      continue;
    }
    scene.views_.push_back(std::move(view));
  }
  if (scene.views_.empty()) {
    return FailedPreconditionError("render: none of the " + std::to_string(layers.size()) +
                                   " views has valid depth (no drawable segment)");
  }
  if (static_cast<int>(scene.views_.size()) > ViewMesh::kMaxViews) {
    return InvalidArgumentError("render: " + std::to_string(scene.views_.size()) + " views, at most " +
                                std::to_string(ViewMesh::kMaxViews));
  }
  std::vector<Eigen::Vector3d> centres;
  std::vector<Eigen::Matrix3d> rotations;
  for (const SceneView& view : scene.views_) {
    centres.push_back(CameraCentre(view.cam_from_world));
    rotations.push_back(view.cam_from_world.RotationMatrix().transpose());
  }
  PX_ASSIGN_OR_RETURN(scene.mesh_, ViewMesh::Build(centres, rotations));
  // rho from the percentiles (so one stray plane does not decide), with a floor for flat scenes.
  const DepthPercentiles depths = SceneDepthPercentiles(scene.views_);
  scene.near_m_ = depths.near_m;
  scene.far_m_ = depths.far_m;
  const double rho = options.depth_range_m > 0 ? options.depth_range_m
                                               : std::max(depths.far_m - depths.near_m, 0.01 * depths.median_m);
  scene.soft_z_ = SoftZ(rho, options.soft_z_gamma_fraction);
  if (options.consistent_blend.enabled || options.measure_double_images) {
    scene.contradicted_texels_ =
        FindContradictions(options.consistent_blend, scene.mesh_.SlotNeighbours(), &scene.views_);
  }
  return scene;
}

}  // namespace px::render
