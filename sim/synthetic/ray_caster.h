// A deterministic CPU ray caster for synthetic scenes: renders what any camera (pinhole or
// distorted, at any pose) sees, with its exact per-pixel depth. It makes the simulated lattice
// views and also ground-truth images of novel cameras for evaluating the renderer.
//
// Colour: ss x ss stratified rays per pixel (at the centres of the strata) find the edges;
// textures are filtered to the ray footprint (mip levels, band-limited procedurals). Where all
// of a pixel's rays and its 8 neighbours' centre rays hit the same surface it is shaded once, at
// its centre, with a pixel-wide texture filter (multisample anti-aliasing); an edge pixel is the
// box-filtered mean of 8 x 8 rays over it, as a sensor pixel integrates its coverage.
// Depth: z (camera frame, metres) of the surface hit by the ray through the pixel centre,
// 0 where it hits nothing. Rows are rendered in parallel (cv::parallel_for_); every pixel is
// computed independently, so the output is bit-identical for any thread count.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "pipeline/core/camera_model.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/status.h"
#include "sim/synthetic/scene.h"

namespace px::sim {

struct RenderOptions {
  static constexpr int kMaxSupersampling = 8;
  int supersampling = 2;  // rays per pixel side, [1, 8]: 2 -> 4 rays per pixel
  double mip_bias = 0.0;  // added to the texture level, [-4, 4]; > 0 blurs, < 0 sharpens (aliases)
  Status Validate() const;
};

struct RenderedView {
  cv::Mat bgr;      // CV_8UC3
  cv::Mat depth_m;  // CV_32F, z in the camera frame, 0 = nothing hit
};

// The viewing rays of a camera at unit depth, (x, y, 1) in the camera frame, for every pixel
// centre and every supersample. With distortion they come from CameraModel::Unproject (costly:
// iterative), so they are computed once and shared by every view with the same intrinsics.
class CameraRays {
 public:
  static StatusOr<CameraRays> Make(const CameraModel& camera, int supersampling);

  const CameraModel& camera() const { return camera_; }
  int supersampling() const { return supersampling_; }
  // Rays per pixel in the table: the pixel centre first, then the ss x ss samples row-major.
  int rays_per_pixel() const { return supersampling_ * supersampling_ + 1; }
  // Unit-depth ray k of pixel (x, y).
  void Ray(int x, int y, int k, double* rx, double* ry) const {
    if (table_.empty()) {
      double px = x, py = y;
      if (k > 0) {
        px += StratumOffset((k - 1) % supersampling_, supersampling_);
        py += StratumOffset((k - 1) / supersampling_, supersampling_);
      }
      *rx = (px - camera_.cx) / camera_.fx;
      *ry = (py - camera_.cy) / camera_.fy;
      return;
    }
    const float* entry = table_.data() + ((static_cast<size_t>(y) * camera_.width + x) * rays_per_pixel() + k) * 2;
    *rx = entry[0];
    *ry = entry[1];
  }
  // Offset of stratum i of n from the pixel centre, in pixels (strata centres).
  static double StratumOffset(int i, int n) { return (i + 0.5) / n - 0.5; }

 private:
  CameraModel camera_;
  int supersampling_ = 1;
  std::vector<float> table_;  // 2 floats per ray; empty for a pinhole (computed on the fly)
};

// Renders `scene` as seen by `camera` at `cam_from_world`.
StatusOr<RenderedView> RenderView(const Scene& scene,
                                  const CameraModel& camera,
                                  const Rigid3& cam_from_world,
                                  const RenderOptions& options = {});
// The same with precomputed rays (the supersampling is the rays'); mip_bias as in RenderOptions.
RenderedView RenderView(const Scene& scene,
                        const CameraRays& rays,
                        const Rigid3& cam_from_world,
                        double mip_bias = 0.0);

}  // namespace px::sim
