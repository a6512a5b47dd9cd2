// The simulated lattice sensor: renders every lens's upright view of a scene, then applies what
// a real multi-lens sensor does to it (vignetting, per-lens exposure, noise, inverted tiles,
// dark gaps) and encodes the frame in the sensor's pixel format. The clean renders and their
// depths are the ground truth.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "pipeline/core/camera_model.h"
#include "pipeline/core/pixel_format.h"
#include "pipeline/core/rig_calibration.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/view.h"
#include "sim/synthetic/scene.h"
#include "sim/synthetic/sim_camera.h"

namespace px::sim {

struct ViewTruth {
  ViewId id;            // row-major lattice index
  CameraModel camera;   // intrinsics of the upright tile, with the spec's distortion
  Rigid3 cam_from_rig;  // world = rig frame
  cv::Mat bgr;          // clean upright render: no vignetting, exposure gain or noise; CV_8UC3
  cv::Mat depth_m;      // CV_32F, z in this lens's camera frame, 0 where nothing was hit
};

struct GroundTruth {
  std::string scene_name;
  RigCalibration rig;                  // the lenses the views used: spec.TrueCalibration()
  std::vector<ViewTruth> views;        // one per lens, row-major
  std::vector<double> exposure_gains;  // per view, applied on the sensor
  uint64_t noise_seed = 0;             // the seed of this frame's noise
};

struct SensorFrame {
  RawImage sensor;  // the whole sensor in the requested pixel format
  GroundTruth truth;
};

// Renders each lens's clean upright view (spec.supersampling) through spec.TrueCalibration().
// Fails on an invalid spec.
StatusOr<std::vector<ViewTruth>> RenderLatticeViews(const Scene& scene, const SimCameraSpec& spec);

// Per-lens exposure gains in [1 - s, 1 + s], s = spec.exposure_spread, drawn from `seed`.
std::vector<double> DrawExposureGains(const SimCameraSpec& spec, uint64_t seed);

// The sensor image (CV_8UC3 BGR, spec.Layout() size): each clean view times the vignetting and
// its exposure gain, plus Gaussian noise drawn from `noise_seed`, placed in its tile in the
// tile's orientation (kRotated180: the upright view turned by 180 degrees); the rest is the
// dark gap level with its own slight noise. Deterministic for given seeds.
cv::Mat ComposeSensorBgr(const SimCameraSpec& spec,
                         const std::vector<ViewTruth>& views,
                         const std::vector<double>& exposure_gains,
                         uint64_t noise_seed);

// The noise seed a capture with this sequence number uses (sequence 0 for RenderSensorFrame).
uint64_t CaptureNoiseSeed(uint64_t seed, uint64_t sequence);

// Everything at once: renders, draws gains from `seed`, composes with CaptureNoiseSeed(seed, 0)
// and encodes in spec.pixel_format.
StatusOr<SensorFrame> RenderSensorFrame(const Scene& scene, const SimCameraSpec& spec, uint64_t seed);

// Turns an upright tile image into its stored orientation on the sensor, or back (every
// orientation is its own inverse).
cv::Mat OrientTile(const cv::Mat& image, TileOrientation orientation);

}  // namespace px::sim
