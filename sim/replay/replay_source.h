// Plays recordings back through the FrameSource interface: each Next() returns the next
// recording's frame set (in name order for a folder of recordings), looping if asked.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <vector>

#include "capture/recording.h"
#include "drivers/source/frame_source.h"

namespace px {

struct ReplayOptions {
  bool loop = true;  // after the last recording, start again; false: Next() returns OUT_OF_RANGE
  // Recordings kept decoded in memory, in bytes (in name order until the budget is spent); the
  // rest are read from disk again on each Next(). 0 = read every recording on each Next().
  uint64_t max_cached_bytes = uint64_t{256} << 20;
};

// `path` is one recording folder, or a folder whose subfolders are recordings.
// Fails when no recording there can be read, naming the first error. Unreadable subfolders are
// skipped with a warning that names their error.
//
// The source ("replay") describes itself as the first recording's source with model
// "replay:<path>". Configure grants the first recording's pixel format, size (of its first ok
// frame) and frame count (kAdjusted when asked for anything else: replay cannot convert) and
// rewinds to the first recording. Next() returns the recordings in order, exactly as recorded
// (capture id, sequence, timestamps, per-frame status), after CheckFrameSet against the granted
// configuration marks frames of a recording that differs; `timeout` is not used (reads do not
// wait on a camera). FAILED_PRECONDITION before Configure and after Stop.
StatusOr<std::unique_ptr<FrameSource>> OpenReplaySource(const std::filesystem::path& path,
                                                        const ReplayOptions& options = {});

}  // namespace px
