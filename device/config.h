// The daemon's configuration: every field has a default, so an empty JSON object (or no file at
// all) is a working config. Lookup order (README "Configuration"): --config FILE, else the file
// named by $PARALLAX_CONFIG, else the built-in defaults; command-line overrides apply last.
#pragma once

#include <cstdint>
#include <filesystem>
#include <nlohmann/json_fwd.hpp>
#include <string>

#include "device/storage/storage_layout.h"
#include "pipeline/core/status.h"

namespace px::device {

// The simulated lattice camera (sim/synthetic).
struct SimSourceSettings {
  std::filesystem::path scene;  // scene JSON (sim/scenes/*.json); empty = the synthetic source's default
  std::string camera = "pop9";  // preset: "pop9" (3x3, 640x480 tiles) or "integral5x4" (5x4, 320x240)
  int tile_width = 0;           // pixels per tile, 0 = the preset's; the focal length scales with it
  int tile_height = 0;          // 0 = the preset's
  uint64_t seed = 1;            // noise and exposure draws
};

// Recorded captures played back (sim/replay).
struct ReplaySourceSettings {
  std::filesystem::path path;  // one recording folder, or a folder of recordings
  bool loop = true;            // start again after the last recording
};

struct SourceSettings {
  std::string kind = "sim";  // "sim" or "replay"
  SimSourceSettings sim;
  ReplaySourceSettings replay;
  int timeout_ms = 10000;  // how long one capture may take before it fails, (0, 600000]
};

// What the clip looks like (pipeline/direct, pipeline/clip).
struct ClipSettings {
  std::string move = "auto";        // camera move, see pipeline/direct/direct_options.h
  double duration_s = 3.0;          // clip length in seconds, (0, 60]
  double fps = 30.0;                // frames per second, (0, 240]
  int crf = 20;                     // x264 quality, [0, 51]; lower is better and larger
  std::string preset = "veryfast";  // x264 preset, ultrafast .. veryslow
  int num_threads = 0;              // pipeline threads, 0 = all cores
};

struct DaemonConfig {
  StorageOptions storage;                                               // JSON: storage.root, storage.min_free_mb
  std::filesystem::path control_socket = "/run/parallax/control.sock";  // JSON: control.socket; "" = no socket
  SourceSettings source;
  ClipSettings clip;
  std::string log_levels = "info";  // JSON: log.levels, e.g. "info" or "info,depth=debug"

  // Checks ranges and names; errors name the JSON field ("clip.fps: 0 is not in (0, 240]").
  Status Validate() const;
};

// Parses a config object. Absent fields keep their defaults; unknown fields and wrong types are
// errors naming the field ("source.sim.camra: unknown field (known: scene, camera, ...)").
StatusOr<DaemonConfig> DaemonConfigFromJson(const nlohmann::json& j);
// The effective config, every field written (what --print-config shows).
nlohmann::json DaemonConfigToJson(const DaemonConfig& config);

// Reads and parses a config file; errors name the file.
StatusOr<DaemonConfig> LoadDaemonConfigFile(const std::filesystem::path& path);

struct ConfigSource {
  DaemonConfig config;
  std::string origin;  // "--config /etc/parallax.json", "$PARALLAX_CONFIG=/x.json", "built-in defaults"
};

// Applies the lookup order: `flag_path` if non-empty, else `env_value` (the value of
// $PARALLAX_CONFIG, nullptr or empty when unset), else the defaults.
StatusOr<ConfigSource> ResolveDaemonConfig(const std::string& flag_path, const char* env_value);

}  // namespace px::device
