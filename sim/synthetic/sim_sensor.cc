#include "sim/synthetic/sim_sensor.h"

#include <chrono>
#include <cmath>
#include <opencv2/core.hpp>
#include <optional>

#include "pipeline/core/log.h"
#include "sim/synthetic/ray_caster.h"

namespace px::sim {
namespace {

// SplitMix64 finaliser: decorrelates seeds that differ in a few bits.
uint64_t MixSeed(uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

uint64_t StreamSeed(uint64_t seed, uint64_t stream) { return MixSeed(MixSeed(seed) ^ MixSeed(stream + 0x51ed27)); }

constexpr uint64_t kGainStream = 1;
constexpr uint64_t kGapStream = 2;
constexpr uint64_t kTileStreamBase = 1000;

// gain = 1 - v (r / r_corner)^2 about the principal point, 3 channels.
cv::Mat VignettingGain(const CameraModel& camera, double vignetting) {
  cv::Mat gain(camera.height, camera.width, CV_32FC3);
  const double corner_x = std::max(camera.cx, camera.width - 1 - camera.cx);
  const double corner_y = std::max(camera.cy, camera.height - 1 - camera.cy);
  const double r2_corner = corner_x * corner_x + corner_y * corner_y;
  for (int y = 0; y < camera.height; ++y) {
    cv::Vec3f* row = gain.ptr<cv::Vec3f>(y);
    for (int x = 0; x < camera.width; ++x) {
      const double dx = x - camera.cx, dy = y - camera.cy;
      const float g = static_cast<float>(1.0 - vignetting * (dx * dx + dy * dy) / r2_corner);
      row[x] = cv::Vec3f(g, g, g);
    }
  }
  return gain;
}

}  // namespace

cv::Mat OrientTile(const cv::Mat& image, TileOrientation orientation) {
  cv::Mat out;
  switch (orientation) {
    case TileOrientation::kUpright:
      out = image.clone();
      break;
    case TileOrientation::kRotated180:
      cv::flip(image, out, -1);
      break;
    case TileOrientation::kMirroredX:
      cv::flip(image, out, 1);
      break;
    case TileOrientation::kMirroredY:
      cv::flip(image, out, 0);
      break;
  }
  return out;
}

uint64_t CaptureNoiseSeed(uint64_t seed, uint64_t sequence) { return StreamSeed(seed, 0x10000 + sequence); }

StatusOr<std::vector<ViewTruth>> RenderLatticeViews(const Scene& scene, const SimCameraSpec& spec) {
  PX_RETURN_IF_ERROR(spec.Validate());
  const auto start = std::chrono::steady_clock::now();
  const RigCalibration rig = spec.TrueCalibration();
  // Lenses with equal intrinsics (all of them, unless perturbed) share one table of rays; a
  // perturbed lens gets its own, made when its turn comes (a distorted table is ~12 MB).
  std::optional<CameraRays> rays;
  std::vector<ViewTruth> views;
  for (int i = 0; i < rig.NumViews(); ++i) {
    const CameraModel& camera = rig.lenses[i].camera;
    if (!rays || rays->camera().fx != camera.fx || rays->camera().fy != camera.fy || rays->camera().cx != camera.cx ||
        rays->camera().cy != camera.cy || rays->camera().distortion != camera.distortion) {
      PX_ASSIGN_OR_RETURN(CameraRays table, CameraRays::Make(camera, spec.supersampling));
      rays = std::move(table);
    }
    RenderedView rendered = RenderView(scene, *rays, rig.lenses[i].cam_from_rig);
    ViewTruth view;
    view.id = ViewId{i};
    view.camera = rig.lenses[i].camera;
    view.cam_from_rig = rig.lenses[i].cam_from_rig;
    view.bgr = rendered.bgr;
    view.depth_m = rendered.depth_m;
    views.push_back(std::move(view));
  }
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  Logger("sim")->info("rendered '{}' through {}: {} views {}x{} ss{} in {:.0f} ms",
                      scene.name,
                      spec.name,
                      views.size(),
                      spec.tile_width,
                      spec.tile_height,
                      spec.supersampling,
                      ms);
  return views;
}

std::vector<double> DrawExposureGains(const SimCameraSpec& spec, uint64_t seed) {
  cv::RNG rng(StreamSeed(seed, kGainStream));
  std::vector<double> gains;
  for (int i = 0; i < spec.rows * spec.cols; ++i) {
    const double u = rng.uniform(0.0, 1.0);
    gains.push_back(1.0 + spec.exposure_spread * (2.0 * u - 1.0));
  }
  return gains;
}

cv::Mat ComposeSensorBgr(const SimCameraSpec& spec,
                         const std::vector<ViewTruth>& views,
                         const std::vector<double>& exposure_gains,
                         uint64_t noise_seed) {
  const LatticeLayout layout = spec.Layout();
  PX_CHECK(static_cast<int>(views.size()) == layout.NumViews() &&
           static_cast<int>(exposure_gains.size()) == layout.NumViews())
      << "got " << views.size() << " views and " << exposure_gains.size() << " gains for " << layout.NumViews()
      << " tiles";
  cv::Mat sensor(layout.sensor_height, layout.sensor_width, CV_8UC3);
  if (spec.gap_noise_sigma > 0) {
    cv::RNG gap_rng(StreamSeed(noise_seed, kGapStream));
    gap_rng.fill(sensor, cv::RNG::NORMAL, cv::Scalar::all(spec.gap_level), cv::Scalar::all(spec.gap_noise_sigma));
  } else {
    sensor.setTo(cv::Scalar::all(spec.gap_level));
  }
  const cv::Mat vignette = spec.vignetting > 0 ? VignettingGain(views[0].camera, spec.vignetting) : cv::Mat();
  // Tiles are independent (own noise stream each), so they can be composed in parallel.
  cv::parallel_for_(cv::Range(0, layout.NumViews()), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      const Tile& tile = layout.tiles[i];
      cv::Mat value;
      views[i].bgr.convertTo(value, CV_32FC3, exposure_gains[i]);
      if (!vignette.empty()) cv::multiply(value, vignette, value);
      if (spec.noise_sigma > 0) {
        cv::Mat noise(value.size(), CV_32FC3);
        cv::RNG rng(StreamSeed(noise_seed, kTileStreamBase + i));
        rng.fill(noise, cv::RNG::NORMAL, cv::Scalar::all(0), cv::Scalar::all(spec.noise_sigma));
        value += noise;
      }
      cv::Mat upright;
      value.convertTo(upright, CV_8UC3);  // rounds and saturates
      OrientTile(upright, tile.orientation).copyTo(sensor(tile.rect));
    }
  });
  return sensor;
}

StatusOr<SensorFrame> RenderSensorFrame(const Scene& scene, const SimCameraSpec& spec, uint64_t seed) {
  PX_ASSIGN_OR_RETURN(std::vector<ViewTruth> views, RenderLatticeViews(scene, spec));
  SensorFrame frame;
  frame.truth.scene_name = scene.name;
  frame.truth.rig = spec.TrueCalibration();
  frame.truth.exposure_gains = DrawExposureGains(spec, seed);
  frame.truth.noise_seed = CaptureNoiseSeed(seed, 0);
  frame.truth.views = std::move(views);
  const cv::Mat bgr = ComposeSensorBgr(spec, frame.truth.views, frame.truth.exposure_gains, frame.truth.noise_seed);
  PX_ASSIGN_OR_RETURN(frame.sensor, FromBgr(bgr, spec.pixel_format));
  return frame;
}

}  // namespace px::sim
