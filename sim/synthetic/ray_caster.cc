#include "sim/synthetic/ray_caster.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "sim/synthetic/procedural.h"

namespace px::sim {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kMinT = 1e-4;  // metres of depth: nothing is rendered closer than 0.1 mm
constexpr int kBlockSize = 16;  // pixels per side of the blocks that share one object cull
// Rays per side with which a pixel whose ss x ss rays disagree (an edge) is rendered again: a
// sensor pixel integrates the coverage of an edge, which 2 x 2 rays estimate in steps of a
// quarter at a phase that differs from view to view (noise no renderer of the views can
// predict; pipeline/render/README.md).
constexpr int kEdgeSupersampling = 8;

using Vec3 = Eigen::Vector3d;

// Per-view object data: everything that depends only on the camera centre is precomputed, so
// a ray-object test is a handful of multiply-adds.
struct ViewPlane {
  Vec3 normal, right, down;
  double numerator;  // normal . (centre - origin)
  double s0, q0;     // origin's coordinates along right / down, relative to the centre
  double half_w, half_h;
  const Plane* plane;
};

struct ViewBox {
  Eigen::Matrix3d box_from_world;
  Vec3 origin_in_box;
  Vec3 half;
  const Box* box;
};

struct ViewSphere {
  Vec3 origin_minus_centre;
  double c;  // |o - centre|^2 - r^2
  const Sphere* sphere;
};

enum class HitKind { kNone, kPlane, kBox, kSphere, kBackdrop };

// The objects a block of pixels can see, in scene order (so ties resolve as without culling).
struct Candidates {
  std::vector<int> planes, boxes, spheres;
  void Clear() {
    planes.clear();
    boxes.clear();
    spheres.clear();
  }
};

struct BoundingSphere {
  Vec3 centre_in_cam;
  double radius;
};

struct Hit {
  double t = kInf;
  HitKind kind = HitKind::kNone;
  int index = -1;
  int face = 0;         // boxes: 2 * axis + (1 if the +axis side), so face edges count as edges
  double s = 0, q = 0;  // plane coordinates at the hit (planes only)

  bool SameSurface(const Hit& other) const { return kind == other.kind && index == other.index && face == other.face; }
};

// Surface data the material needs.
struct SurfacePoint {
  double s_m = 0, q_m = 0;  // surface coordinates in metres (procedurals)
  double u = 0, v = 0;      // texture coordinates in [0, 1] over the surface
  double texels_per_m = 1;  // texture density at level 0 (mip selection)
  bool wrap = false;
  Vec3 normal;  // unit, world
};

class ViewTracer {
 public:
  ViewTracer(const Scene& scene, const Vec3& origin, const Eigen::Matrix3d& cam_from_world_rotation)
      : scene_(scene), origin_(origin) {
    auto bound = [&](const Vec3& centre, double radius) {
      return BoundingSphere{cam_from_world_rotation * (centre - origin), radius};
    };
    for (const Plane& p : scene.planes)
      plane_bounds_.push_back(bound(p.centre_m, 0.5 * std::hypot(p.width_m, p.height_m)));
    for (const Box& b : scene.boxes) box_bounds_.push_back(bound(b.centre_m, b.half_size_m.norm()));
    for (const Sphere& s : scene.spheres) sphere_bounds_.push_back(bound(s.centre_m, s.radius_m));
    for (const Plane& p : scene.planes) {
      const Vec3 rel = origin - p.centre_m;
      planes_.push_back({p.normal,
                         p.right,
                         p.down,
                         -p.normal.dot(rel),
                         p.right.dot(rel),
                         p.down.dot(rel),
                         0.5 * p.width_m,
                         0.5 * p.height_m,
                         &p});
    }
    for (const Box& b : scene.boxes) {
      const Eigen::Matrix3d box_from_world = b.world_from_box.transpose();
      boxes_.push_back({box_from_world, box_from_world * (origin - b.centre_m), b.half_size_m, &b});
    }
    for (const Sphere& s : scene.spheres) {
      const Vec3 oc = origin - s.centre_m;
      spheres_.push_back({oc, oc.squaredNorm() - s.radius_m * s.radius_m, &s});
    }
  }

  // Keeps the objects whose bounding sphere meets the cone of directions around unit `axis`
  // (camera frame) with half-angle `half_angle` radians: nothing else can be hit by those rays.
  void Cull(const Vec3& axis, double half_angle, Candidates* out) const {
    out->Clear();
    auto visible = [&](const BoundingSphere& b) {
      const double dist = b.centre_in_cam.norm();
      if (dist <= b.radius) return true;
      const double angle = std::acos(std::clamp(axis.dot(b.centre_in_cam) / dist, -1.0, 1.0));
      return angle <= half_angle + std::asin(b.radius / dist) + 1e-6;
    };
    for (size_t i = 0; i < plane_bounds_.size(); ++i)
      if (visible(plane_bounds_[i])) out->planes.push_back(static_cast<int>(i));
    for (size_t i = 0; i < box_bounds_.size(); ++i)
      if (visible(box_bounds_[i])) out->boxes.push_back(static_cast<int>(i));
    for (size_t i = 0; i < sphere_bounds_.size(); ++i)
      if (visible(sphere_bounds_[i])) out->spheres.push_back(static_cast<int>(i));
  }

  // Nearest hit among `candidates` along origin + t d, t in (kMinT, inf). `d` has unit depth in
  // the camera frame, so t is the depth z of the hit.
  Hit Trace(const Vec3& d, const Candidates& candidates) const {
    Hit hit;
    for (const int i : candidates.planes) {
      const ViewPlane& p = planes_[i];
      const double denom = p.normal.dot(d);
      if (denom == 0.0) continue;
      const double t = p.numerator / denom;
      if (!(t > kMinT && t < hit.t)) continue;
      const double s = p.s0 + t * p.right.dot(d);
      if (std::abs(s) > p.half_w) continue;
      const double q = p.q0 + t * p.down.dot(d);
      if (std::abs(q) > p.half_h) continue;
      hit.t = t;
      hit.kind = HitKind::kPlane;
      hit.index = i;
      hit.s = s;
      hit.q = q;
    }
    for (const int i : candidates.boxes) {
      const ViewBox& b = boxes_[i];
      const Vec3 dl = b.box_from_world * d;
      double t_near = -kInf, t_far = kInf;
      int near_face = 0, far_face = 0;
      bool miss = false;
      for (int k = 0; k < 3; ++k) {
        if (dl[k] == 0.0) {
          if (std::abs(b.origin_in_box[k]) > b.half[k]) miss = true;
          continue;
        }
        const double inv = 1.0 / dl[k];
        // Entering through the face that looks against the ray, leaving through the other.
        const double t0 = (-b.half[k] - b.origin_in_box[k]) * inv;
        const double t1 = (b.half[k] - b.origin_in_box[k]) * inv;
        const bool positive = dl[k] > 0;
        const double enter = positive ? t0 : t1, leave = positive ? t1 : t0;
        if (enter > t_near) t_near = enter, near_face = 2 * k + (positive ? 0 : 1);
        if (leave < t_far) t_far = leave, far_face = 2 * k + (positive ? 1 : 0);
      }
      if (miss || t_near > t_far) continue;
      const bool from_inside = !(t_near > kMinT);
      const double t = from_inside ? t_far : t_near;
      if (!(t > kMinT && t < hit.t)) continue;
      hit.t = t;
      hit.kind = HitKind::kBox;
      hit.index = i;
      hit.face = from_inside ? far_face : near_face;
    }
    const double a = d.squaredNorm();
    for (const int i : candidates.spheres) {
      const ViewSphere& s = spheres_[i];
      const double b = s.origin_minus_centre.dot(d);
      const double disc = b * b - a * s.c;
      if (disc < 0) continue;
      const double root = std::sqrt(disc);
      double t = (-b - root) / a;
      if (!(t > kMinT)) t = (-b + root) / a;
      if (!(t > kMinT && t < hit.t)) continue;
      hit.t = t;
      hit.kind = HitKind::kSphere;
      hit.index = i;
    }
    if (scene_.backdrop && d.z() > 0) {
      const double t = (scene_.backdrop->distance_m - origin_.z()) / d.z();
      if (t > kMinT && t < hit.t) {
        hit.t = t;
        hit.kind = HitKind::kBackdrop;
        hit.index = -1;
      }
    }
    return hit;
  }

  // Colour of the hit for a ray d that stands for a patch `ray_spacing` wide at unit depth.
  cv::Vec3f Shade(const Hit& hit, const Vec3& d, double ray_spacing, double mip_bias) const {
    int material_index = 0;
    SurfacePoint sp = Surface(hit, d, &material_index);
    const Material& m = scene_.materials[material_index];
    // d has unit depth, so 1/|d| is the cosine of its angle to the optical axis. A patch of
    // `ray_spacing` at unit depth covers t * ray_spacing on a fronto-parallel surface at depth t,
    // stretched by cos(off-axis) / cos(incidence) along the slant: use the geometric mean of the
    // two axes, a compromise between blur and aliasing on slanted surfaces.
    const double inv_norm = 1.0 / d.norm();
    const double cos_incidence = std::abs(sp.normal.dot(d)) * inv_norm;
    const double footprint_m =
        hit.t * ray_spacing * std::sqrt(std::max(inv_norm, 0.05) / std::max(cos_incidence, 0.05));
    cv::Vec3f albedo;
    switch (m.kind) {
      case MaterialKind::kFlat:
        albedo = m.bgr_a;
        break;
      case MaterialKind::kChecker: {
        const float w = FilteredChecker(sp.s_m, sp.q_m, m.scale_m, footprint_m);
        albedo = m.bgr_a + (m.bgr_b - m.bgr_a) * w;
        break;
      }
      case MaterialKind::kNoise: {
        const auto stretch = [&m](float n) {
          return std::clamp(static_cast<float>(0.5 + (n - 0.5) * m.contrast), 0.0f, 1.0f);
        };
        const float n = stretch(FractalNoise(sp.s_m, sp.q_m, m.scale_m, m.octaves, m.persistence, footprint_m, m.seed));
        albedo = m.bgr_a + (m.bgr_b - m.bgr_a) * n;
        if (m.mix_c > 0) {
          // An independent, coarser field tints regions towards the third colour.
          const float n2 = stretch(FractalNoise(sp.s_m + 31.7,
                                                sp.q_m - 12.9,
                                                1.7 * m.scale_m,
                                                m.octaves,
                                                m.persistence,
                                                footprint_m,
                                                m.seed ^ 0x5bd1e995U));
          albedo += (m.bgr_c - albedo) * (n2 * m.mix_c);
        }
        break;
      }
      case MaterialKind::kGradient: {
        const double x = (sp.s_m * m.direction.x() + sp.q_m * m.direction.y()) / m.scale_m + 0.5;
        albedo = m.bgr_a + (m.bgr_b - m.bgr_a) * static_cast<float>(std::clamp(x, 0.0, 1.0));
        break;
      }
      case MaterialKind::kTexture: {
        const double level = std::log2(std::max(footprint_m * sp.texels_per_m, 1e-9)) + mip_bias;
        albedo = m.texture->Sample(sp.u, sp.v, level, sp.wrap);
        break;
      }
    }
    if (!m.lit) return albedo;
    // Two-sided Lambertian: the normal that faces the viewer.
    const double facing = sp.normal.dot(d) > 0 ? -1.0 : 1.0;
    const double lambert = std::max(0.0, facing * sp.normal.dot(scene_.light.towards_light));
    return albedo * static_cast<float>(scene_.light.ambient + scene_.light.diffuse * lambert);
  }

 private:
  SurfacePoint Surface(const Hit& hit, const Vec3& d, int* material_index) const {
    SurfacePoint sp;
    double width_m = 1, height_m = 1;
    const Material* m = nullptr;
    switch (hit.kind) {
      case HitKind::kPlane: {
        const ViewPlane& p = planes_[hit.index];
        *material_index = p.plane->material;
        sp.normal = p.normal;
        sp.s_m = hit.s;
        sp.q_m = hit.q;
        width_m = p.plane->width_m;
        height_m = p.plane->height_m;
        break;
      }
      case HitKind::kBox: {
        const ViewBox& b = boxes_[hit.index];
        *material_index = b.box->material;
        const Vec3 local = b.origin_in_box + hit.t * (b.box_from_world * d);
        const int axis = hit.face / 2;
        const double sign = (hit.face % 2 == 1) ? 1.0 : -1.0;
        Vec3 n_local = Vec3::Zero();
        n_local[axis] = sign;
        sp.normal = b.box->world_from_box * n_local;
        // In-face axes chosen so a face seen from outside, upright, is not mirrored.
        static constexpr int kUAxis[3] = {2, 0, 0}, kVAxis[3] = {1, 2, 1};
        const int ua = kUAxis[axis], va = kVAxis[axis];
        const double u_sign = axis == 1 ? 1.0 : (axis == 0 ? sign : -sign);
        sp.s_m = u_sign * local[ua];
        sp.q_m = local[va];
        width_m = 2 * b.half[ua];
        height_m = 2 * b.half[va];
        break;
      }
      case HitKind::kSphere: {
        const ViewSphere& s = spheres_[hit.index];
        const double r = s.sphere->radius_m;
        *material_index = s.sphere->material;
        const Vec3 local = s.origin_minus_centre + hit.t * d;  // hit - centre
        sp.normal = local / r;
        // Longitude from the -z pole (facing the camera), so the seam is at the back.
        const double longitude = std::atan2(local.x(), -local.z());
        const double colatitude = std::acos(std::clamp(local.y() / r, -1.0, 1.0));
        sp.s_m = longitude * r;
        sp.q_m = (colatitude - M_PI / 2) * r;
        width_m = 2 * M_PI * r;
        height_m = M_PI * r;
        break;
      }
      case HitKind::kBackdrop: {
        *material_index = scene_.backdrop->material;
        const Vec3 p = origin_ + hit.t * d;
        sp.normal = Vec3(0, 0, -1);
        sp.s_m = p.x();
        sp.q_m = p.y();
        width_m = height_m = 2 * scene_.backdrop->distance_m;  // a stretched texture spans 90 degrees
        break;
      }
      case HitKind::kNone:
        break;
    }
    m = &scene_.materials[*material_index];
    if (m->kind == MaterialKind::kTexture) {
      const double tex_w = m->texture->width(), tex_h = m->texture->height();
      if (m->tile_m.x() > 0) {
        sp.u = sp.s_m / m->tile_m.x() + 0.5;
        sp.v = sp.q_m / m->tile_m.y() + 0.5;
        sp.wrap = true;
        sp.texels_per_m = std::max(tex_w / m->tile_m.x(), tex_h / m->tile_m.y());
      } else {
        sp.u = sp.s_m / width_m + 0.5;
        sp.v = sp.q_m / height_m + 0.5;
        sp.wrap = hit.kind == HitKind::kSphere;
        sp.texels_per_m = std::max(tex_w / width_m, tex_h / height_m);
      }
    }
    return sp;
  }

  const Scene& scene_;
  Vec3 origin_;
  std::vector<ViewPlane> planes_;
  std::vector<ViewBox> boxes_;
  std::vector<ViewSphere> spheres_;
  std::vector<BoundingSphere> plane_bounds_, box_bounds_, sphere_bounds_;
};

}  // namespace

Status RenderOptions::Validate() const {
  if (supersampling < 1 || supersampling > kMaxSupersampling) {
    return InvalidArgumentError("render options: supersampling " + std::to_string(supersampling) + " is not in [1, " +
                                std::to_string(kMaxSupersampling) + "]");
  }
  if (!(mip_bias >= -4 && mip_bias <= 4)) {
    std::ostringstream error;
    error << "render options: mip_bias " << mip_bias << " is not in [-4, 4]";
    return InvalidArgumentError(error.str());
  }
  return OkStatus();
}

StatusOr<CameraRays> CameraRays::Make(const CameraModel& camera, int supersampling) {
  PX_RETURN_IF_ERROR(camera.Validate());
  RenderOptions options;
  options.supersampling = supersampling;
  PX_RETURN_IF_ERROR(options.Validate());
  CameraRays rays;
  rays.camera_ = camera;
  rays.supersampling_ = supersampling;
  if (!camera.HasDistortion()) return rays;
  const int n = rays.rays_per_pixel();
  rays.table_.resize(static_cast<size_t>(camera.width) * camera.height * n * 2);
  float* table = rays.table_.data();
  cv::parallel_for_(cv::Range(0, camera.height), [&](const cv::Range& range) {
    for (int y = range.start; y < range.end; ++y) {
      for (int x = 0; x < camera.width; ++x) {
        float* out = table + (static_cast<size_t>(y) * camera.width + x) * n * 2;
        for (int k = 0; k < n; ++k) {
          double px = x, py = y;
          if (k > 0) {
            px += CameraRays::StratumOffset((k - 1) % supersampling, supersampling);
            py += CameraRays::StratumOffset((k - 1) / supersampling, supersampling);
          }
          const Eigen::Vector3d ray = camera.Unproject(Eigen::Vector2d(px, py));
          out[2 * k] = static_cast<float>(ray.x());
          out[2 * k + 1] = static_cast<float>(ray.y());
        }
      }
    }
  });
  return rays;
}

RenderedView RenderView(const Scene& scene, const CameraRays& rays, const Rigid3& cam_from_world, double mip_bias) {
  const CameraModel& camera = rays.camera();
  const int ss = rays.supersampling();
  const int num_samples = ss * ss;
  PX_CHECK(ss >= 1 && ss <= RenderOptions::kMaxSupersampling) << "supersampling " << ss;
  const Eigen::Matrix3d world_from_cam = cam_from_world.rotation.conjugate().toRotationMatrix();
  const Vec3 origin = CameraCentre(cam_from_world);
  const ViewTracer tracer(scene, origin, cam_from_world.rotation.toRotationMatrix());
  // Neighbouring pixels are 1/f apart at unit depth, supersamples 1/(f ss).
  const double pixel_spacing = 1.0 / (0.5 * (camera.fx + camera.fy));
  const double edge_sample_spacing = pixel_spacing / kEdgeSupersampling;
  const int rays_per_pixel = rays.rays_per_pixel();

  RenderedView out;
  out.bgr.create(camera.height, camera.width, CV_8UC3);
  out.depth_m.create(camera.height, camera.width, CV_32F);
  const int num_bands = (camera.height + kBlockSize - 1) / kBlockSize;
  cv::parallel_for_(cv::Range(0, num_bands), [&](const cv::Range& range) {
    Candidates candidates;
    std::vector<Hit> centre_hits((kBlockSize + 2) * (kBlockSize + 2));
    for (int band = range.start; band < range.end; ++band) {
      const int y0 = band * kBlockSize, y1 = std::min(camera.height, y0 + kBlockSize);
      for (int x0 = 0; x0 < camera.width; x0 += kBlockSize) {
        const int x1 = std::min(camera.width, x0 + kBlockSize);
        // The cone of this block's rays: around its middle ray, as wide as its widest ray.
        double rx, ry;
        rays.Ray((x0 + x1) / 2, (y0 + y1) / 2, 0, &rx, &ry);
        const Vec3 axis = Vec3(rx, ry, 1.0).normalized();
        double min_cos = 1.0;
        for (int y = y0; y < y1; ++y) {
          for (int x = x0; x < x1; ++x) {
            for (int k = 0; k < rays_per_pixel; ++k) {
              rays.Ray(x, y, k, &rx, &ry);
              min_cos =
                  std::min(min_cos, (axis.x() * rx + axis.y() * ry + axis.z()) / std::sqrt(rx * rx + ry * ry + 1));
            }
          }
        }
        // Widened by a pixel: the neighbours' centre rays and the edge rays reach further out.
        tracer.Cull(axis, std::acos(std::clamp(min_cos, -1.0, 1.0)) + pixel_spacing, &candidates);

        // The centre hits of the block and of a one-pixel border around it: an edge that crosses
        // a pixel between its strata still parts it from a neighbour's centre.
        const int cx0 = std::max(0, x0 - 1), cx1 = std::min(camera.width, x1 + 1);
        const int cy0 = std::max(0, y0 - 1), cy1 = std::min(camera.height, y1 + 1);
        const int centres_stride = cx1 - cx0;
        for (int y = cy0; y < cy1; ++y) {
          for (int x = cx0; x < cx1; ++x) {
            rays.Ray(x, y, 0, &rx, &ry);
            centre_hits[(y - cy0) * centres_stride + (x - cx0)] =
                tracer.Trace(world_from_cam * Vec3(rx, ry, 1.0), candidates);
          }
        }
        const auto centre_hit = [&](int x, int y) -> const Hit& {
          return centre_hits[(y - cy0) * centres_stride + (x - cx0)];
        };

        for (int y = y0; y < y1; ++y) {
          cv::Vec3b* bgr_row = out.bgr.ptr<cv::Vec3b>(y);
          float* depth_row = out.depth_m.ptr<float>(y);
          for (int x = x0; x < x1; ++x) {
            rays.Ray(x, y, 0, &rx, &ry);
            const double rx0 = rx, ry0 = ry;
            const Vec3 centre_dir = world_from_cam * Vec3(rx, ry, 1.0);
            const Hit& centre = centre_hit(x, y);
            // Geometry is supersampled; where every sample and every neighbour's centre sees the
            // same surface as the centre, the pixel is shaded once with a pixel-wide texture
            // filter (as multisampling does), else it is an edge (below).
            bool coherent = true;
            if (ss > 1) {
              for (int ny = std::max(cy0, y - 1); ny <= std::min(cy1 - 1, y + 1) && coherent; ++ny) {
                for (int nx = std::max(cx0, x - 1); nx <= std::min(cx1 - 1, x + 1); ++nx) {
                  coherent = coherent && centre_hit(nx, ny).SameSurface(centre);
                }
              }
              for (int k = 0; k < num_samples && coherent; ++k) {
                rays.Ray(x, y, k + 1, &rx, &ry);
                coherent = tracer.Trace(world_from_cam * Vec3(rx, ry, 1.0), candidates).SameSurface(centre);
              }
            }
            cv::Vec3f colour;
            if (coherent) {
              colour = centre.kind == HitKind::kNone ? scene.background_bgr
                                                     : tracer.Shade(centre, centre_dir, pixel_spacing, mip_bias);
            } else {
              // An edge: the pixel's coverage integrated on a kEdgeSupersampling grid, its rays
              // from the strata's affine fit (exact for a pinhole, to second order with
              // distortion), each shaded with its own footprint.
              const Vec3 centre_cam(rx0, ry0, 1.0);
              double jx[2] = {0, 0}, jy[2] = {0, 0}, norm = 0;  // d ray / d offset, per axis
              for (int k = 0; k < num_samples; ++k) {
                double sx, sy;
                rays.Ray(x, y, k + 1, &sx, &sy);
                const double ox = CameraRays::StratumOffset(k % ss, ss), oy = CameraRays::StratumOffset(k / ss, ss);
                jx[0] += (sx - rx0) * ox;
                jx[1] += (sy - ry0) * ox;
                jy[0] += (sx - rx0) * oy;
                jy[1] += (sy - ry0) * oy;
                norm += ox * ox;
              }
              for (double& v : jx) v /= norm;
              for (double& v : jy) v /= norm;
              cv::Vec3f sum(0, 0, 0);
              for (int k = 0; k < kEdgeSupersampling * kEdgeSupersampling; ++k) {
                const double ox = CameraRays::StratumOffset(k % kEdgeSupersampling, kEdgeSupersampling);
                const double oy = CameraRays::StratumOffset(k / kEdgeSupersampling, kEdgeSupersampling);
                const Vec3 dir =
                    world_from_cam * (centre_cam + Vec3(jx[0] * ox + jy[0] * oy, jx[1] * ox + jy[1] * oy, 0));
                const Hit hit = tracer.Trace(dir, candidates);
                sum += hit.kind == HitKind::kNone ? scene.background_bgr
                                                  : tracer.Shade(hit, dir, edge_sample_spacing, mip_bias);
              }
              colour = sum * (1.0f / static_cast<float>(kEdgeSupersampling * kEdgeSupersampling));
            }
            bgr_row[x] = cv::Vec3b(cv::saturate_cast<uchar>(colour[0]),
                                   cv::saturate_cast<uchar>(colour[1]),
                                   cv::saturate_cast<uchar>(colour[2]));
            depth_row[x] = centre.kind == HitKind::kNone ? 0.0f : static_cast<float>(centre.t);
          }
        }
      }
    }
  });
  return out;
}

StatusOr<RenderedView> RenderView(const Scene& scene,
                                  const CameraModel& camera,
                                  const Rigid3& cam_from_world,
                                  const RenderOptions& options) {
  PX_RETURN_IF_ERROR(options.Validate());
  PX_ASSIGN_OR_RETURN(CameraRays rays, CameraRays::Make(camera, options.supersampling));
  return RenderView(scene, rays, cam_from_world, options.mip_bias);
}

}  // namespace px::sim
