// The simulated multi-lens camera as a FrameSource: renders a scene (JSON) through a
// configurable lattice camera onto one sensor frame per Next().
#pragma once

#include <filesystem>
#include <memory>
#include <string>

#include "drivers/source/clock.h"
#include "drivers/source/frame_source.h"
#include "sim/synthetic/sim_camera.h"
#include "sim/synthetic/sim_sensor.h"

namespace px {

struct SyntheticSourceOptions {
  SimCameraSpec camera = SimCameraSpec::Pop9();  // lattice, optics, sensor effects
  std::filesystem::path scene_file;              // scene JSON (sim/scenes/*.json); empty = still_life.json
                                                 // in sim::ScenesDir()
  uint64_t seed = 1;                             // noise and exposure draws; same seed, same bytes
  Clock* clock = nullptr;                        // timestamps; nullptr = a SteadyClock
};

// Loads the scene now (errors name the file and field) and renders on the first Next(); the
// clean render is cached, each capture adds its own noise (seed, sequence). Describe() gives
// model "sim:<camera.name>", a lattice frame and camera.Calibration() (the factory's: with
// perturbed lenses the views differ from it; LastGroundTruth has the truth). Configure grants any
// pixel format that fits the sensor and always the native sensor size (kAdjusted otherwise).
// Next() never times out: rendering is not a camera that can miss a frame.
StatusOr<std::unique_ptr<FrameSource>> MakeSyntheticSource(const SyntheticSourceOptions& options);

// The ground truth of the last frame `source` delivered: clean upright views, depths, poses,
// exposure gains. INVALID_ARGUMENT if `source` is not a synthetic source, FAILED_PRECONDITION
// before its first capture. For tests and evaluation.
StatusOr<sim::GroundTruth> LastGroundTruth(const FrameSource& source);

}  // namespace px
