// The soak: presses the button N times through the real parallaxd executable and its control
// socket (simulated camera, tiny tiles, short clips, a storage quota so the disk use stays
// bounded) and reports what a camera that runs for months must show: every press handled, every
// capture made into a clip (none lost), and resident memory that stays flat.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "pipeline/core/status.h"

namespace px::device {

struct SoakOptions {
  std::filesystem::path parallaxd;  // the executable
  std::filesystem::path work_dir;   // config, storage, socket and the daemon's log go here
  int presses = 1000;               // [1, 1000000]
  int tile_width = 96;              // simulated Pop9 tiles, [32, 640]
  int tile_height = 72;             // [24, 480]
  int clip_frames = 2;              // frames per clip at 10 fps, [1, 300]
  int in_flight = 4;                // presses queued before the oldest is waited for, [1, 64]
  double quota_mb = 20;             // storage.quota_mb; old clips are evicted beyond it, > 0
  int progress_every = 100;         // log a line every this many presses; 0 = never

  Status Validate() const;
};

struct SoakReport {
  int presses = 0;                    // presses sent
  int handled = 0;                    // acknowledged with a job id
  int clips = 0;                      // jobs that ended done
  int lost = 0;                       // acknowledged presses that did not end in a clip
  std::vector<std::string> failures;  // "000042: <error>", the first 10
  uint64_t rss_start_bytes = 0;       // after the first clip (libraries and caches loaded)
  uint64_t rss_half_bytes = 0;        // when half the presses were made (the warm-up is over by then)
  uint64_t rss_end_bytes = 0;         // after the last clip
  uint64_t rss_peak_bytes = 0;        // the largest sample (one after every finished job)
  uint64_t store_bytes = 0;           // under the storage root at the end
  int evicted = 0;                    // clips the quota evicted
  double seconds = 0;
  int daemon_exit_code = -1;  // after {"cmd":"quit"}

  // RSS growth from start to end, in MB (10^6 bytes; negative when it shrank).
  double RssGrowthMb() const { return (static_cast<double>(rss_end_bytes) - rss_start_bytes) / 1e6; }
  // Growth over the second half: what a leak per press would show once caches are warm.
  double RssSecondHalfGrowthMb() const { return (static_cast<double>(rss_end_bytes) - rss_half_bytes) / 1e6; }
  std::string ToText() const;  // the figures, one per line
};

// INVALID_ARGUMENT for bad options; UNAVAILABLE when the daemon does not start or dies (with the
// log's tail). A lost capture is a figure in the report, not an error.
StatusOr<SoakReport> RunSoak(const SoakOptions& options);

}  // namespace px::device
