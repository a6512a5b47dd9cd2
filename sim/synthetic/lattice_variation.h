// Lattices as real multi-lens cameras make them: tiles slightly unequal in size, offset from the
// regular grid and turned by a degree or so (lenses and masks mounted by hand). The varied
// layout is the ground truth that lattice detection is measured against.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "pipeline/core/lattice_layout.h"
#include "pipeline/core/status.h"
#include "sim/synthetic/sim_camera.h"
#include "sim/synthetic/sim_sensor.h"

namespace px::sim {

struct LatticeVariation {
  double max_offset_px = 0;     // each tile's centre moves by up to this in x and y, [0, gap_px / 2)
  double max_size_change = 0;   // each tile's width and height scale by up to +- this fraction, [0, 0.2]
  double max_rotation_deg = 0;  // each tile turns by up to +- this, [0, 5]
  int outer_margin_px = -1;     // the margin around the lattice; -1 = the spec's gap_px
  uint64_t seed = 1;

  Status Validate() const;
};

// spec.Layout() with every tile varied (uniform draws from `variation.seed`). The sensor keeps the
// spec's size when outer_margin_px is -1; otherwise it grows or shrinks by the margin's change.
// INVALID_ARGUMENT when the variation is out of range, or the varied tiles overlap or leave the
// sensor (the message names the tile).
StatusOr<LatticeLayout> VariedLayout(const SimCameraSpec& spec, const LatticeVariation& variation);

// Like ComposeSensorBgr, onto any layout of spec.rows x spec.cols tiles: each tile's upright view
// (with exposure gain, vignetting and noise) is resized to the tile's rect, put in its
// orientation and turned by its rotation_deg about the rect's centre (bilinear); the rest of the
// sensor is the spec's gap level with its noise.
cv::Mat ComposeSensorOnLayout(const SimCameraSpec& spec,
                              const LatticeLayout& layout,
                              const std::vector<ViewTruth>& views,
                              const std::vector<double>& exposure_gains,
                              uint64_t noise_seed);

}  // namespace px::sim
