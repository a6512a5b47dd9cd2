#include "pipeline/render/novel_view_renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

#include <Eigen/Dense>

#include "pipeline/core/log.h"
#include "pipeline/render/hole_fill.h"
#include "pipeline/render/soft_z.h"

namespace px {

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
// Points closer than this to a camera's centre plane are not projected (1 mm).
constexpr float kMinDepthM = 1e-3f;

// Maps pixel (u, v) of camera A seen at depth z to camera B: q = z * h * (u, v, 1) + e, with
// q = (x * w, y * w, w) and w the depth in B. Both cameras are pinholes.
struct Warp {
  Eigen::Matrix3f h;
  Eigen::Vector3f e;
};

Warp MakeWarp(const CameraModel& from_camera, const Rigid3& from_cam_from_world, const CameraModel& to_camera,
              const Rigid3& to_cam_from_world) {
  const Rigid3 to_from_from = to_cam_from_world * from_cam_from_world.Inverse();
  const Eigen::Matrix3d to_k = to_camera.K();
  Warp warp;
  warp.h = (to_k * to_from_from.RotationMatrix() * from_camera.K().inverse()).cast<float>();
  warp.e = (to_k * to_from_from.translation).cast<float>();
  return warp;
}

// A source chosen for one frame, with its weight and its warps to and from the target.
struct Chosen {
  int index = 0;
  float view_weight = 0;
  Warp to_target;
  Warp from_target;
  float focal_ratio = 1;  // target fx / source fx: a source pixel's size in the target at equal depth
  std::vector<float> quad_min_y;  // per source quad row: target y range of its quads (empty: +inf..-inf)
  std::vector<float> quad_max_y;
};

inline float Min4(float a, float b, float c, float d) { return std::min(std::min(a, b), std::min(c, d)); }
inline float Max4(float a, float b, float c, float d) { return std::max(std::max(a, b), std::max(c, d)); }
// floor and ceil for values well inside the int range (callers clamp first); std::floor without
// SSE4.1 costs several times more and runs four times per quad.
inline int FloorToInt(float v) {
  const int i = static_cast<int>(v);
  return i - (v < static_cast<float>(i) ? 1 : 0);
}
inline int CeilToInt(float v) {
  const int i = static_cast<int>(v);
  return i + (v > static_cast<float>(i) ? 1 : 0);
}

}  // namespace

StatusOr<std::unique_ptr<NovelViewRenderer>> NovelViewRenderer::Create(const std::vector<View>& views,
                                                                       const std::vector<DepthMap>& depths,
                                                                       const RenderOptions& options) {
  PX_RETURN_IF_ERROR(options.Validate());
  if (views.empty()) return InvalidArgumentError("render: no source views");
  std::vector<Source> sources;
  for (const View& view : views) {
    const std::string name = "render: view " + std::to_string(view.id.value);
    PX_RETURN_IF_ERROR(view.camera.Validate().WithContext(name));
    if (view.camera.HasDistortion()) {
      return InvalidArgumentError(name + ": camera has lens distortion; the renderer needs undistorted views");
    }
    if (view.image.type() != CV_8UC3 || view.image.cols != view.camera.width ||
        view.image.rows != view.camera.height) {
      return InvalidArgumentError(name + ": image is " + std::to_string(view.image.cols) + "x" +
                                  std::to_string(view.image.rows) + " type " + std::to_string(view.image.type()) +
                                  ", want " + std::to_string(view.camera.width) + "x" +
                                  std::to_string(view.camera.height) + " CV_8UC3");
    }
    for (const Source& other : sources) {
      if (other.id == view.id) return InvalidArgumentError(name + ": id appears twice");
    }
    const auto depth = std::find_if(depths.begin(), depths.end(), [&](const DepthMap& d) { return d.id == view.id; });
    if (depth == depths.end()) return InvalidArgumentError(name + ": no depth map with this id");
    if (depth->depth_m.type() != CV_32F || depth->depth_m.size() != view.image.size()) {
      return InvalidArgumentError(name + ": depth map is " + std::to_string(depth->depth_m.cols) + "x" +
                                  std::to_string(depth->depth_m.rows) + " type " +
                                  std::to_string(depth->depth_m.type()) + ", want CV_32F of the image size");
    }
    if (!depth->confidence.empty() &&
        (depth->confidence.type() != CV_32F || depth->confidence.size() != view.image.size())) {
      return InvalidArgumentError(name + ": confidence must be CV_32F of the image size or empty");
    }
    if (view.camera.width < 2 || view.camera.height < 2) {
      return InvalidArgumentError(name + ": image must be at least 2x2");
    }
    Source source;
    source.id = view.id;
    source.image = view.image;
    source.depth_m = depth->depth_m;
    source.confidence = depth->confidence;
    source.camera = view.camera;
    source.cam_from_world = view.cam_from_world;
    source.centre_in_world = CameraCentre(view.cam_from_world);
    sources.push_back(std::move(source));
  }
  return std::unique_ptr<NovelViewRenderer>(new NovelViewRenderer(std::move(sources), options));
}

StatusOr<RenderResult> NovelViewRenderer::Render(const CameraModel& target_camera,
                                                 const Rigid3& target_cam_from_world, ViewId excluded) {
  PX_RETURN_IF_ERROR(target_camera.Validate().WithContext("render: target camera"));
  if (target_camera.HasDistortion()) return InvalidArgumentError("render: target camera has lens distortion");
  const int width = target_camera.width;
  const int height = target_camera.height;
  const Eigen::Vector3d target_centre = CameraCentre(target_cam_from_world);

  // Nearest sources by camera centre, and blending weights that reach zero as a source is about
  // to be swapped for the next one (unstructured lumigraph style), so a moving camera does not
  // pop when the chosen set changes.
  std::vector<std::pair<double, int>> by_distance;
  for (int i = 0; i < NumSources(); ++i) {
    if (sources_[i].id == excluded) continue;
    by_distance.emplace_back((sources_[i].centre_in_world - target_centre).norm(), i);
  }
  if (by_distance.empty()) return FailedPreconditionError("render: no source view left after the exclusion");
  std::sort(by_distance.begin(), by_distance.end());
  const int num_chosen = std::min<int>(options_.num_source_views, static_cast<int>(by_distance.size()));
  // Softening distance: a tenth of the mean spacing of the chosen sources from their nearest
  // neighbour keeps a source at the target's position from taking an infinite weight.
  double spacing_sum = 0;
  int spacing_count = 0;
  for (int a = 0; a < num_chosen; ++a) {
    double nearest = std::numeric_limits<double>::infinity();
    for (int b = 0; b < NumSources(); ++b) {
      if (b == by_distance[a].second) continue;
      const double d = (sources_[b].centre_in_world - sources_[by_distance[a].second].centre_in_world).norm();
      if (d > 0) nearest = std::min(nearest, d);
    }
    if (std::isfinite(nearest)) {
      spacing_sum += nearest;
      ++spacing_count;
    }
  }
  const double soften_m = spacing_count > 0 ? 0.1 * spacing_sum / spacing_count : 1e-3;
  const double cutoff = num_chosen < static_cast<int>(by_distance.size())
                            ? 1.0 / (by_distance[num_chosen].first + soften_m)
                            : 0.0;
  std::vector<Chosen> chosen(num_chosen);
  float max_weight = 0;
  for (int j = 0; j < num_chosen; ++j) {
    Chosen& c = chosen[j];
    c.index = by_distance[j].second;
    c.view_weight = static_cast<float>(std::max(0.0, 1.0 / (by_distance[j].first + soften_m) - cutoff));
    max_weight = std::max(max_weight, c.view_weight);
    const Source& s = sources_[c.index];
    c.to_target = MakeWarp(s.camera, s.cam_from_world, target_camera, target_cam_from_world);
    c.from_target = MakeWarp(target_camera, target_cam_from_world, s.camera, s.cam_from_world);
    c.focal_ratio = static_cast<float>(target_camera.fx / s.camera.fx);
  }
  // Sources tied with the first one left out weigh (almost) nothing in the blend but still fill
  // pixels no other source sees.
  for (Chosen& c : chosen) {
    c.view_weight = max_weight > 0 ? std::max(c.view_weight, 1e-3f * max_weight) : 1.0f;
  }

  using Clock = std::chrono::steady_clock;
  const auto ms_since = [](Clock::time_point since) {
    return std::chrono::duration<double, std::milli>(Clock::now() - since).count();
  };
  const Clock::time_point start = Clock::now();

  // Pass 1: project every source pixel with known depth into the target.
  scratch_.projected.resize(num_chosen);
  scratch_.z_buffer.resize(num_chosen);
  std::vector<int> row_offset(num_chosen + 1, 0);
  for (int j = 0; j < num_chosen; ++j) {
    const Source& s = sources_[chosen[j].index];
    scratch_.projected[j].create(s.camera.height, s.camera.width, CV_32FC3);
    row_offset[j + 1] = row_offset[j] + s.camera.height;
  }
  std::vector<std::vector<float>> row_min_y(num_chosen), row_max_y(num_chosen);
  for (int j = 0; j < num_chosen; ++j) {
    row_min_y[j].assign(sources_[chosen[j].index].camera.height, kInf);
    row_max_y[j].assign(sources_[chosen[j].index].camera.height, -kInf);
  }
  cv::parallel_for_(cv::Range(0, row_offset.back()), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      const int j = static_cast<int>(std::upper_bound(row_offset.begin(), row_offset.end(), i) - row_offset.begin()) - 1;
      const int v = i - row_offset[j];
      const Source& s = sources_[chosen[j].index];
      const Warp& warp = chosen[j].to_target;
      const Eigen::Vector3f base = warp.h.col(1) * static_cast<float>(v) + warp.h.col(2);
      const Eigen::Vector3f step = warp.h.col(0);
      const float* depth = s.depth_m.ptr<float>(v);
      cv::Vec3f* out = scratch_.projected[j].ptr<cv::Vec3f>(v);
      float min_y = kInf, max_y = -kInf;
      for (int u = 0; u < s.camera.width; ++u) {
        const float z = depth[u];
        if (!(z > 0) || !std::isfinite(z)) {
          out[u] = cv::Vec3f(0, 0, 0);
          continue;
        }
        const Eigen::Vector3f q = z * (base + static_cast<float>(u) * step) + warp.e;
        if (!(q.z() > kMinDepthM)) {
          out[u] = cv::Vec3f(0, 0, 0);
          continue;
        }
        const float inv = 1.0f / q.z();
        out[u] = cv::Vec3f(q.x() * inv, q.y() * inv, q.z());
        min_y = std::min(min_y, out[u][1]);
        max_y = std::max(max_y, out[u][1]);
      }
      row_min_y[j][v] = min_y;
      row_max_y[j][v] = max_y;
    }
  });
  for (int j = 0; j < num_chosen; ++j) {
    const int rows = static_cast<int>(row_min_y[j].size());
    chosen[j].quad_min_y.resize(rows - 1);
    chosen[j].quad_max_y.resize(rows - 1);
    for (int v = 0; v + 1 < rows; ++v) {
      chosen[j].quad_min_y[v] = std::min(row_min_y[j][v], row_min_y[j][v + 1]);
      chosen[j].quad_max_y[v] = std::max(row_max_y[j][v], row_max_y[j][v + 1]);
    }
    scratch_.z_buffer[j].create(height, width, CV_32F);
  }

  const double project_ms = ms_since(start);

  // Pass 2: rasterise each source's pixel quads into its own z-buffer. Each stripe of target rows
  // is one task that visits only the source rows landing on it, so no two tasks write one pixel.
  const int num_stripes = std::max(1, std::min(height, 4 * cv::getNumThreads()));
  cv::parallel_for_(cv::Range(0, num_stripes), [&](const cv::Range& range) {
    for (int stripe = range.start; stripe < range.end; ++stripe) {
      const int y_begin = stripe * height / num_stripes;
      const int y_end = (stripe + 1) * height / num_stripes;
      const float y_first = static_cast<float>(y_begin), y_last = static_cast<float>(y_end - 1);
      const float x_limit = static_cast<float>(width), y_limit = static_cast<float>(height);
      for (int j = 0; j < num_chosen; ++j) {
        scratch_.z_buffer[j].rowRange(y_begin, y_end).setTo(kInf);
        const Source& s = sources_[chosen[j].index];
        const float stretch_ratio = static_cast<float>(options_.max_splat_stretch) * chosen[j].focal_ratio;
        const cv::Mat& projected = scratch_.projected[j];
        cv::Mat& z_buffer = scratch_.z_buffer[j];
        for (int v = 0; v + 1 < s.camera.height; ++v) {
          if (chosen[j].quad_max_y[v] < y_first || chosen[j].quad_min_y[v] > y_last) continue;
          const cv::Vec3f* r0 = projected.ptr<cv::Vec3f>(v);
          const cv::Vec3f* r1 = projected.ptr<cv::Vec3f>(v + 1);
          const float* depth = s.depth_m.ptr<float>(v);
          for (int u = 0; u + 1 < s.camera.width; ++u) {
            const cv::Vec3f& p00 = r0[u];
            const cv::Vec3f& p10 = r0[u + 1];
            const cv::Vec3f& p01 = r1[u];
            const cv::Vec3f& p11 = r1[u + 1];
            if (p00[2] <= 0 || p10[2] <= 0 || p01[2] <= 0 || p11[2] <= 0) continue;
            const float min_y = Min4(p00[1], p10[1], p01[1], p11[1]);
            const float max_y = Max4(p00[1], p10[1], p01[1], p11[1]);
            if (max_y < y_first || min_y > y_last) continue;
            const float min_x = Min4(p00[0], p10[0], p01[0], p11[0]);
            const float max_x = Max4(p00[0], p10[0], p01[0], p11[0]);
            // A fronto-parallel pixel at source depth d seen at target depth z spans
            // focal_ratio * d / z target pixels; much more means the quad bridges a depth edge.
            const float extent = std::max(max_x - min_x, max_y - min_y);
            if (extent * p00[2] > stretch_ratio * depth[u]) continue;
            // Clamp before converting: a box may lie far outside the image.
            const int x0 = std::max(0, CeilToInt(std::clamp(min_x, -1.0f, x_limit)));
            const int x1 = std::min(width - 1, FloorToInt(std::clamp(max_x, -1.0f, x_limit)));
            const int y0 = std::max(y_begin, CeilToInt(std::clamp(min_y, -1.0f, y_limit)));
            const int y1 = std::min(y_end - 1, FloorToInt(std::clamp(max_y, -1.0f, y_limit)));
            if (x0 > x1 || y0 > y1) continue;
            // One depth per quad: across one pixel even a steeply slanted surface changes depth
            // by well under 1 %, which moves the backward colour lookup by a hundredth of a pixel.
            const float z = 0.25f * (p00[2] + p10[2] + p01[2] + p11[2]);
            for (int y = y0; y <= y1; ++y) {
              float* zrow = z_buffer.ptr<float>(y);
              for (int x = x0; x <= x1; ++x) zrow[x] = std::min(zrow[x], z);
            }
          }
        }
      }
    }
  });

  const double splat_ms = ms_since(start) - project_ms;

  // Pass 3: soft z-buffer across the sources, backward colour sampling, blend.
  RenderResult result;
  result.bgr.create(height, width, CV_8UC3);
  result.depth_m.create(height, width, CV_32F);
  result.coverage.create(height, width, CV_8U);
  const float band = static_cast<float>(options_.soft_z_band);
  // Raw access per chosen source, hoisted out of the per-pixel loop.
  struct Sampler {
    const cv::Mat* image;
    const cv::Mat* confidence;  // nullptr: confidence 1
    float max_u, max_v;         // last pixel centre
    bool significant;           // weight at least 1 % of the largest
  };
  std::vector<Sampler> samplers(num_chosen);
  for (int j = 0; j < num_chosen; ++j) {
    const Source& s = sources_[chosen[j].index];
    samplers[j] = {&s.image, s.confidence.empty() ? nullptr : &s.confidence, s.camera.width - 1.0f,
                   s.camera.height - 1.0f, chosen[j].view_weight >= 0.01f * max_weight};
  }
  cv::parallel_for_(cv::Range(0, height), [&](const cv::Range& range) {
    std::vector<const float*> zrows(num_chosen);
    std::vector<Eigen::Vector3f> row_base(num_chosen);
    for (int y = range.start; y < range.end; ++y) {
      for (int j = 0; j < num_chosen; ++j) {
        zrows[j] = scratch_.z_buffer[j].ptr<float>(y);
        row_base[j] = chosen[j].from_target.h.col(1) * static_cast<float>(y) + chosen[j].from_target.h.col(2);
      }
      cv::Vec3b* out_bgr = result.bgr.ptr<cv::Vec3b>(y);
      float* out_z = result.depth_m.ptr<float>(y);
      uint8_t* out_cov = result.coverage.ptr<uint8_t>(y);
      for (int x = 0; x < width; ++x) {
        float sum_w = 0, sum_z = 0, sum_b = 0, sum_g = 0, sum_r = 0;
        // The sources that matter for this viewpoint decide alone where any of them sees the
        // pixel: a source of negligible weight neither colours it nor, through a wrong depth,
        // hides their surface. The others only fill what the first ones do not see.
        for (int pass = 0; pass < 2 && sum_w == 0; ++pass) {
          const bool want_significant = pass == 0;
          float z_near = kInf;
          for (int j = 0; j < num_chosen; ++j) {
            if (samplers[j].significant == want_significant) z_near = std::min(z_near, zrows[j][x]);
          }
          if (!(z_near < kInf)) continue;
          for (int j = 0; j < num_chosen; ++j) {
            if (samplers[j].significant != want_significant) continue;
            const float z = zrows[j][x];
            if (!(z < kInf)) continue;
            const float w_z = render::SoftZWeight((z - z_near) / z_near, band);
            if (w_z <= 0) continue;
            const Warp& warp = chosen[j].from_target;
            const Eigen::Vector3f q = z * (row_base[j] + static_cast<float>(x) * warp.h.col(0)) + warp.e;
            if (!(q.z() > kMinDepthM)) continue;
            const float inv = 1.0f / q.z();
            float u = q.x() * inv, v = q.y() * inv;
            const Sampler& sampler = samplers[j];
            // Quads end at the outermost pixel centres; allow rounding just past them.
            if (!(u > -0.01f && v > -0.01f && u < sampler.max_u + 0.01f && v < sampler.max_v + 0.01f)) continue;
            u = std::clamp(u, 0.0f, sampler.max_u);
            v = std::clamp(v, 0.0f, sampler.max_v);
            const int u0 = std::min(static_cast<int>(u), static_cast<int>(sampler.max_u) - 1);
            const int v0 = std::min(static_cast<int>(v), static_cast<int>(sampler.max_v) - 1);
            const float fu = u - static_cast<float>(u0), fv = v - static_cast<float>(v0);
            const uint8_t* c0 = sampler.image->ptr<uint8_t>(v0) + 3 * u0;
            const uint8_t* c1 = sampler.image->ptr<uint8_t>(v0 + 1) + 3 * u0;
            const float w00 = (1 - fu) * (1 - fv), w10 = fu * (1 - fv), w01 = (1 - fu) * fv, w11 = fu * fv;
            float confidence = 1.0f;
            if (sampler.confidence != nullptr) {
              confidence = sampler.confidence->ptr<float>(static_cast<int>(v + 0.5f))[static_cast<int>(u + 0.5f)];
            }
            // Unsure depth still renders where nothing else does, but yields to sure depth.
            const float w = w_z * chosen[j].view_weight * (0.1f + 0.9f * std::clamp(confidence, 0.0f, 1.0f));
            sum_w += w;
            sum_z += w * z;
            sum_b += w * (w00 * c0[0] + w10 * c0[3] + w01 * c1[0] + w11 * c1[3]);
            sum_g += w * (w00 * c0[1] + w10 * c0[4] + w01 * c1[1] + w11 * c1[4]);
            sum_r += w * (w00 * c0[2] + w10 * c0[5] + w01 * c1[2] + w11 * c1[5]);
          }
        }
        if (sum_w > 0) {
          const float inv = 1.0f / sum_w;
          out_bgr[x] = cv::Vec3b(cv::saturate_cast<uint8_t>(sum_b * inv), cv::saturate_cast<uint8_t>(sum_g * inv),
                                 cv::saturate_cast<uint8_t>(sum_r * inv));
          out_z[x] = sum_z * inv;
          out_cov[x] = 255;
        } else {
          out_bgr[x] = cv::Vec3b(0, 0, 0);
          out_z[x] = 0;
          out_cov[x] = 0;
        }
      }
    }
  });

  const double blend_ms = ms_since(start) - project_ms - splat_ms;
  const int covered = cv::countNonZero(result.coverage);
  result.hole_ratio = 1.0 - static_cast<double>(covered) / (static_cast<double>(width) * height);
  if (covered < width * height) {
    result.hole_score = render::HoleScore(result.coverage);
    render::FillHoles(result.coverage, options_.hole_fill_radius_px, band, &result.bgr, &result.depth_m);
  }
  for (const Chosen& c : chosen) result.sources.push_back(sources_[c.index].id);
  Logger("render")->debug("frame {}x{} from {} sources: project {:.1f} ms, splat {:.1f} ms, blend {:.1f} ms, "
                          "holes {:.2f}% filled in {:.1f} ms",
                          width, height, num_chosen, project_ms, splat_ms, blend_ms, 100 * result.hole_ratio,
                          ms_since(start) - project_ms - splat_ms - blend_ms);
  return result;
}

StatusOr<RenderResult> RenderNovelView(const std::vector<View>& views, const std::vector<DepthMap>& depths,
                                       const CameraModel& target_camera, const Rigid3& target_cam_from_world,
                                       const RenderOptions& options) {
  PX_ASSIGN_OR_RETURN(std::unique_ptr<NovelViewRenderer> renderer,
                      NovelViewRenderer::Create(views, depths, options));
  return renderer->Render(target_camera, target_cam_from_world);
}

}  // namespace px
