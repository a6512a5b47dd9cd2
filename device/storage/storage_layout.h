// Where the daemon keeps its files, all under one root:
//   <root>/captures/<id>/   the raw capture as a recording (capture/FORMAT.md), written first
//   <root>/clips/<id>.mp4   the finished clip (.gif or .webp, or the folder <id>/ of PNG frames,
//                           with another clip.format)
//   <root>/clips/<id>.json  the camera path and the pipeline report for that clip
//   <root>/jobs/<id>.json   the journal: one record per job (job_journal.h)
#pragma once

#include <sys/types.h>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "pipeline/core/status.h"

namespace px::device {

struct StorageOptions {
  std::filesystem::path root = "/var/lib/parallax";  // absolute or relative to the working folder
  uint64_t min_free_bytes = 200ull * 1000 * 1000;    // refuse a capture with less free under root; >= 0
  // At most this many bytes under root (captures, clips, journal); 0 = no quota. Oldest done jobs
  // are evicted to stay under it (storage_quota.h); unprocessed captures never are.
  uint64_t quota_bytes = 0;
  // The group given read access to the store; nullopt: the daemon's own (config: storage.group).
  std::optional<gid_t> group;
  Status Validate() const;
};

class StorageLayout {
 public:
  // `root` is made absolute (so logged and announced paths are absolute).
  explicit StorageLayout(const std::filesystem::path& root);

  const std::filesystem::path& root() const { return root_; }
  std::filesystem::path CapturesDir() const { return root_ / "captures"; }
  std::filesystem::path ClipsDir() const { return root_ / "clips"; }
  std::filesystem::path JobsDir() const { return root_ / "jobs"; }
  // The owner's settings for the next presses (device/press_settings.h).
  std::filesystem::path SettingsPath() const { return root_ / "settings.json"; }

  std::filesystem::path CaptureDir(const std::string& job_id) const { return CapturesDir() / job_id; }
  std::filesystem::path ClipPath(const std::string& job_id) const { return ClipsDir() / (job_id + ".mp4"); }
  // The job's clip as it exists on disk in whichever format it was made (mp4, gif, webp, or a
  // folder of PNG frames); ClipPath() when there is none.
  std::filesystem::path FindClip(const std::string& job_id) const;
  std::filesystem::path JobRecordPath(const std::string& job_id) const { return JobsDir() / (job_id + ".json"); }

  // Creates the folders (fsyncing each new one into its parent) and removes temporaries that a
  // crashed writer left behind. Errors name the folder. Whatever the caller's umask, the store is
  // the daemon's and its group's alone: the process's umask gains 027 (folders 0750, files 0640
  // from here on) and the four folders are set to 0750, or 02750 owned by `group` (new entries
  // then inherit it), so a store made by an earlier, laxer run is closed too.
  Status Prepare(std::optional<gid_t> group = std::nullopt) const;

 private:
  std::filesystem::path root_;
};

// The report that goes beside a clip: clips/<id>.mp4 -> clips/<id>.json.
std::filesystem::path ClipReportPathFor(const std::filesystem::path& clip_path);
// The still and the small looping preview beside a clip: clips/<id>.poster.jpg and
// clips/<id>.preview.webp (a gallery shows these before the clip itself).
std::filesystem::path ClipPosterPathFor(const std::filesystem::path& clip_path);
std::filesystem::path ClipPreviewPathFor(const std::filesystem::path& clip_path);
// The shot that reproduces the clip exactly (pipeline/direct/SHOT_FORMAT.md), for replaying or
// editing it: clips/<id>.shot.json.
std::filesystem::path ClipShotPathFor(const std::filesystem::path& clip_path);

}  // namespace px::device
