// For tests that run a whole daemon: a config on the simulated camera small enough that a job
// takes seconds, and run flags that make its jobs run in worker processes of the built parallaxd
// (a test binary serves no --job-worker). Needs PX_BINARY_DIR, which px_add_test defines.
#pragma once

#include <filesystem>

#include "device/config.h"
#include "device/daemon_factory.h"

namespace px::device {

// A 3x3 lattice of 160x120 tiles and a 0.5 s clip at 10 fps, stored under `dir`.
inline DaemonConfig SmallDaemonConfig(const std::filesystem::path& dir) {
  DaemonConfig config;
  config.storage.root = dir / "store";
  config.storage.min_free_bytes = 1'000'000;
  config.control_socket = dir / "ctl.sock";
  config.source.sim.tile_width = 160;
  config.source.sim.tile_height = 120;
  config.clip.duration_s = 0.5;
  config.clip.fps = 10;
  config.clip.preset = "ultrafast";
  return config;
}

inline DaemonRunFlags BuiltWorkerFlags() {
  DaemonRunFlags flags;
  flags.worker_binary = std::filesystem::path(PX_BINARY_DIR) / "parallaxd";
  return flags;
}

}  // namespace px::device
