// parallaxd_soak: presses the button N times on the simulated camera through the real daemon and
// its control socket, and prints presses handled, clips made, captures lost and the daemon's RSS.
// Exit status: 0 when nothing was lost and every press was handled, 1 otherwise, 2 for bad flags.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>

#include "device/soak/soak.h"
#include "pipeline/core/log.h"

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  px::device::SoakOptions options;
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  options.parallaxd = ec ? fs::path("parallaxd") : self.parent_path() / "parallaxd";
  options.work_dir = fs::temp_directory_path() / ("parallaxd-soak-" + std::to_string(::getpid()));
  bool keep = false;
  CLI::App app{
      "parallaxd_soak: presses the button N times on the simulated camera through the real parallaxd and "
      "its control socket; prints presses handled, clips made, captures lost (must be 0) and the daemon's "
      "RSS at the start and the end (must stay flat)"};
  app.add_option("--presses", options.presses, "button presses, [1, 1000000]")->capture_default_str();
  app.add_option("--parallaxd", options.parallaxd, "the daemon executable")->capture_default_str();
  app.add_option("--work-dir", options.work_dir, "config, storage, socket and the daemon's log")->capture_default_str();
  app.add_flag("--keep", keep, "keep the work folder afterwards (removed by default)");
  app.add_option("--tile-width", options.tile_width, "simulated Pop9 tile width, [32, 640]")->capture_default_str();
  app.add_option("--tile-height", options.tile_height, "tile height, [24, 480]")->capture_default_str();
  app.add_option("--clip-frames", options.clip_frames, "frames per clip (10 fps), [1, 300]")->capture_default_str();
  app.add_option("--in-flight", options.in_flight, "presses queued before waiting for the oldest, [1, 64]")
      ->capture_default_str();
  app.add_option("--quota-mb", options.quota_mb, "storage.quota_mb: older clips are evicted beyond it")
      ->capture_default_str();
  app.add_option("--progress-every", options.progress_every, "a progress line every N presses (0: none)")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  const bool existed = fs::exists(options.work_dir);
  auto report = px::device::RunSoak(options);
  if (!keep && !existed) fs::remove_all(options.work_dir, ec);
  if (!report.ok()) {
    std::cerr << "parallaxd_soak: " << report.status().ToString() << "\n";
    return report.status().code() == px::StatusCode::kInvalidArgument ? 2 : 1;
  }
  std::cout << report->ToText();
  return report->lost == 0 && report->handled == report->presses ? 0 : 1;
}
