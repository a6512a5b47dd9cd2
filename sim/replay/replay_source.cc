#include "sim/replay/replay_source.h"

#include <algorithm>
#include <chrono>
#include <optional>
#include <string>
#include <system_error>
#include <utility>

#include "pipeline/core/log.h"

namespace px {
namespace {

namespace fs = std::filesystem;

struct ReplayEntry {
  fs::path dir;
  std::optional<Recording> cached;  // empty: read again on each Next()
};

uint64_t RecordingBytes(const Recording& recording) {
  uint64_t bytes = 0;
  for (const Frame& frame : recording.frames.frames) bytes += frame.image.bytes.size();
  return bytes;
}

// The configuration a recording was captured in: its first ok frame's format and size.
SourceConfig RecordedConfig(const Recording& recording) {
  SourceConfig config;
  const std::vector<Frame>& frames = recording.frames.frames;
  auto usable = std::find_if(frames.begin(), frames.end(), [](const Frame& f) { return f.status == FrameStatus::kOk; });
  if (usable == frames.end()) {
    usable = std::find_if(frames.begin(), frames.end(), [](const Frame& f) { return f.image.width > 0; });
  }
  const Frame& frame = usable != frames.end() ? *usable : frames.front();
  config.pixel_format = frame.image.format;
  config.width = frame.image.width;
  config.height = frame.image.height;
  config.shots = recording.frames.kind == FrameSetKind::kImageSet ? static_cast<int>(frames.size()) : 1;
  return config;
}

// True when `granted` is what `wanted` asked for (0 width or height = "native").
bool GrantsWhatWasWanted(const SourceConfig& wanted, const SourceConfig& granted) {
  return wanted.pixel_format == granted.pixel_format && (wanted.width == 0 || wanted.width == granted.width) &&
         (wanted.height == 0 || wanted.height == granted.height) && wanted.shots == granted.shots;
}

class ReplaySource final : public FrameSource {
 public:
  ReplaySource(std::string model,
               std::vector<ReplayEntry> entries,
               SourceDescription description,
               SourceConfig native,
               bool loop)
      : entries_(std::move(entries)), description_(std::move(description)), native_(native), loop_(loop) {
    description_.model = std::move(model);
  }

  std::string_view Name() const override { return "replay"; }
  SourceDescription Describe() const override { return description_; }

  StatusOr<ConfigureResult> Configure(const SourceConfig& wanted, SourceConfig* granted) override {
    if (granted == nullptr) return InvalidArgumentError("replay Configure: granted is null");
    *granted = native_;
    configured_ = true;
    next_ = 0;
    if (GrantsWhatWasWanted(wanted, native_)) return ConfigureResult::kValid;
    Logger("replay")->debug("{}: asked for {}, replaying the recorded {}",
                            description_.model,
                            DescribeConfig(wanted),
                            DescribeConfig(native_));
    return ConfigureResult::kAdjusted;
  }

  StatusOr<FrameSet> Next(std::chrono::milliseconds /*timeout*/) override {
    if (!configured_)
      return FailedPreconditionError(description_.model + ": Next() before Configure() or after Stop()");
    if (next_ == entries_.size()) {
      if (!loop_) {
        return OutOfRangeError(description_.model + ": all " + std::to_string(entries_.size()) +
                               " recording(s) played and looping is off");
      }
      next_ = 0;
    }
    const ReplayEntry& entry = entries_[next_++];
    FrameSet frames;
    if (entry.cached) {
      frames = entry.cached->frames;
    } else {
      // Read again: it was readable at open, so a failure now means it changed on disk.
      StatusOr<Recording> recording = ReadRecording(entry.dir);
      if (!recording.ok()) {
        return UnavailableError(description_.model + ": recording became unreadable: " + recording.status().message());
      }
      frames = std::move(recording->frames);
    }
    // Per-frame problems are data: a recording that differs from the granted configuration
    // comes back with those frames marked, not as an error.
    Status checked = CheckFrameSet(native_, &frames);
    if (!checked.ok()) Logger("replay")->debug("{}: {}", entry.dir.string(), checked.message());
    return frames;
  }

  void Stop() override { configured_ = false; }

 private:
  std::vector<ReplayEntry> entries_;
  SourceDescription description_;
  SourceConfig native_;
  bool loop_;
  bool configured_ = false;
  size_t next_ = 0;
};

// The recording folders under `path`: itself when it holds a manifest, else its subfolders in
// name order.
StatusOr<std::vector<fs::path>> ListRecordingDirs(const fs::path& path) {
  std::error_code ec;
  if (!fs::is_directory(path, ec)) return NotFoundError(path.string() + ": no such folder");
  if (fs::exists(path / "manifest.json", ec)) return std::vector<fs::path>{path};
  std::vector<fs::path> dirs;
  fs::directory_iterator it(path, ec);
  if (ec) return NotFoundError(path.string() + ": cannot list: " + ec.message());
  // increment(ec), not ++: the range-for form throws on a listing error.
  for (; !ec && it != fs::directory_iterator(); it.increment(ec)) {
    std::error_code type_ec;
    if (it->is_directory(type_ec)) dirs.push_back(it->path());
  }
  if (ec) return NotFoundError(path.string() + ": listing failed: " + ec.message());
  std::sort(dirs.begin(), dirs.end());
  if (dirs.empty()) {
    return NotFoundError(path.string() + ": no recordings here (no manifest.json and no subfolders)");
  }
  return dirs;
}

}  // namespace

StatusOr<std::unique_ptr<FrameSource>> OpenReplaySource(const fs::path& path, const ReplayOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  auto log = Logger("replay");
  PX_ASSIGN_OR_RETURN(std::vector<fs::path> dirs, ListRecordingDirs(path));

  std::vector<ReplayEntry> entries;
  std::optional<SourceDescription> description;
  SourceConfig native;
  Status first_error;
  uint64_t cached_bytes = 0;
  for (const fs::path& dir : dirs) {
    StatusOr<Recording> recording = ReadRecording(dir);
    if (!recording.ok()) {
      if (dir == path) return recording.status();  // one recording, named directly
      log->warn("replay {}: skipping {}: {}", path.string(), dir.string(), recording.status().ToString());
      if (first_error.ok()) first_error = recording.status();
      continue;
    }
    const SourceConfig recorded = RecordedConfig(*recording);
    if (!description) {
      description = recording->source;
      native = recorded;
    } else if (recorded != native || recording->source.kind != description->kind) {
      log->warn("replay {}: {} was captured as {} {}, the first recording as {} {}; its frames will be marked",
                path.string(),
                dir.string(),
                FrameSetKindName(recording->source.kind),
                DescribeConfig(recorded),
                FrameSetKindName(description->kind),
                DescribeConfig(native));
    }
    ReplayEntry entry{dir, std::nullopt};
    const uint64_t bytes = RecordingBytes(*recording);
    if (cached_bytes + bytes <= options.max_cached_bytes) {
      cached_bytes += bytes;
      entry.cached = std::move(recording).value();
    }
    entries.push_back(std::move(entry));
  }
  if (entries.empty()) {
    return Status(first_error.code(),
                  path.string() + ": none of " + std::to_string(dirs.size()) +
                      " recording folder(s) is readable; first error: " + first_error.message());
  }
  log->info("replay {}: {} recording(s), {} skipped, {} in memory, {} in {:.0f} ms",
            path.string(),
            entries.size(),
            dirs.size() - entries.size(),
            std::count_if(entries.begin(), entries.end(), [](const ReplayEntry& e) { return e.cached.has_value(); }),
            DescribeConfig(native),
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  return std::unique_ptr<FrameSource>(
      new ReplaySource("replay:" + path.string(), std::move(entries), *std::move(description), native, options.loop));
}

}  // namespace px
