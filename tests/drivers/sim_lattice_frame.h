// A real lattice frame for emulated cameras: the simulated Pop9 (3x3 lenses) with small tiles,
// rendered once per process from sim/scenes/still_life.json, with its factory calibration.
#pragma once

#include <filesystem>
#include <opencv2/core.hpp>

#include "pipeline/core/rig_calibration.h"
#include "sim/synthetic/sim_camera.h"

namespace px::testing {

// Pop9 geometry with 160x120 tiles (sensor 504x384), no noise, one ray per pixel.
SimCameraSpec SmallPop9Spec();

// The sensor frame (BGR, CV_8UC3) the simulated camera delivers; rendered on first use.
StatusOr<cv::Mat> SmallPop9FrameBgr();

// Writes SmallPop9Spec()'s rig calibration as JSON to `path`.
Status WriteSmallPop9Calibration(const std::filesystem::path& path);

}  // namespace px::testing
