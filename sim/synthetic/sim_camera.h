// A simulated multi-lens camera: a lattice of identical pinhole lenses on one sensor, with the
// optical and sensor defects real ones have. Ground truth comes from here, analytically.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "pipeline/core/lattice_layout.h"
#include "pipeline/core/pixel_format.h"
#include "pipeline/core/rig_calibration.h"
#include "sim/synthetic/lens_perturbation.h"

namespace px {

struct SimCameraSpec {
  std::string name = "sim-pop9";
  int rows = 3;
  int cols = 3;
  int tile_width = 640;  // pixels per sub-image
  int tile_height = 480;
  int gap_px = 16;                                             // dark border between tiles and around the frame
  double baseline_m = 0.025;                                   // distance between neighbouring lens centres
  double focal_px = 560.0;                                     // focal length in tile pixels
  TileOrientation orientation = TileOrientation::kRotated180;  // each lens inverts its image
  std::array<double, 5> distortion = {0, 0, 0, 0, 0};          // per-lens, OpenCV order
  double vignetting = 0.0;       // relative fall-off at the tile corner: gain = 1 - v * (r / r_corner)^2
  double exposure_spread = 0.0;  // per-tile gains drawn uniformly in [1 - s, 1 + s] (seeded)
  double noise_sigma = 0.0;      // Gaussian sensor noise, in 8-bit levels (seeded)
  int gap_level = 8;             // dark level of the border between tiles, 8-bit, [0, 255]
  double gap_noise_sigma = 1.0;  // Gaussian noise on the border, 8-bit levels (seeded)
  int supersampling = 2;         // rays per pixel side (2 -> 4 stratified rays per pixel)
  PixelFormat pixel_format = PixelFormat::kRgb888;
  double depth_min_m = 0.5;  // nominal depth range written into the rig calibration
  double depth_max_m = 8.0;
  // 0: the lenses are exactly as Calibration() says. Otherwise the seed of per-lens deviations
  // (`perturbation`): views are rendered through TrueCalibration(), recordings still carry
  // Calibration() (the factory's), the ground truth holds the true lenses.
  uint64_t perturb_lenses_seed = 0;
  LensPerturbation perturbation;

  static SimCameraSpec Pop9();         // 3x3 lattice, 640x480 tiles, 25 mm baseline
  static SimCameraSpec Integral5x4();  // 5 columns x 4 rows, 320x240 tiles, 12 mm baseline
  // Names the first bad field and its value; also checks that the sensor size suits pixel_format.
  Status Validate() const;

  LatticeLayout Layout() const;
  // The ideal (factory) calibration: lens (r, c) at x = (c - (cols-1)/2) * baseline, y likewise,
  // all looking down +z, with the spec's intrinsics and distortion.
  RigCalibration Calibration() const;
  // The lenses the views are rendered through: Calibration(), perturbed when
  // perturb_lenses_seed != 0.
  RigCalibration TrueCalibration() const;
};

}  // namespace px
