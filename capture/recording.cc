#include "capture/recording.h"

#include <chrono>
#include <nlohmann/json.hpp>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "capture/frame_file.h"
#include "capture/recording_manifest.h"
#include "capture/sha256.h"
#include "pipeline/core/json_fields.h"
#include "pipeline/core/log.h"
#include "pipeline/io/durable_file.h"
#include "pipeline/io/image_file.h"

namespace px {
namespace {

namespace fs = std::filesystem;
using capture::FrameEntry;
using capture::Manifest;

// A manifest holds metadata only; anything this large is not one of ours.
constexpr uint64_t kMaxManifestBytes = 64ull << 20;
// A frame file: 2 GiB is far beyond any sensor frame (50 MP x 3 bytes = 150 MB).
constexpr uint64_t kMaxFrameFileBytes = 2ull << 30;

double MillisecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// Removes what a failed write left, unless the write committed. Best effort: the manifest is
// written last, so whatever stays behind is never mistaken for a recording.
class WriteCleanup {
 public:
  explicit WriteCleanup(fs::path dir) : dir_(std::move(dir)) {}
  ~WriteCleanup() {
    if (committed_) return;
    std::error_code ec;
    for (const fs::path& file : files_) {
      fs::remove(file, ec);  // a failed WriteFileAtomically has already removed its temporary
    }
    if (created_dir_) fs::remove(dir_, ec);  // only removes it when empty
  }
  WriteCleanup(const WriteCleanup&) = delete;
  WriteCleanup& operator=(const WriteCleanup&) = delete;

  void AddFile(const fs::path& file) { files_.push_back(file); }
  void SetCreatedDir() { created_dir_ = true; }
  void Commit() { committed_ = true; }

 private:
  fs::path dir_;
  std::vector<fs::path> files_;
  bool created_dir_ = false;
  bool committed_ = false;
};

// The folder must be new or empty; creates it (and its parents) when absent.
Status PrepareFolder(const fs::path& dir, WriteCleanup* cleanup) {
  std::error_code ec;
  const fs::file_status status = fs::status(dir, ec);
  if (fs::exists(status)) {
    if (!fs::is_directory(status)) {
      return Status(StatusCode::kAlreadyExists, dir.string() + ": exists and is not a folder");
    }
    const bool empty = fs::is_empty(dir, ec);
    if (ec) return ErrnoToStatus(ec.value(), "list", dir);
    if (!empty) {
      return Status(StatusCode::kAlreadyExists,
                    dir.string() + ": folder is not empty; a recording needs a new or empty folder");
    }
    return OkStatus();
  }
  fs::create_directories(dir, ec);
  if (ec) return ErrnoToStatus(ec.value(), "create folder", dir);
  cleanup->SetCreatedDir();
  return OkStatus();
}

// Whether the frame's JPEG is the image's own: an ok frame whose JPEG header's size is the image's
// (or turned a quarter, by its EXIF orientation). A JPEG left beside an image changed since is not
// stored, nor one of a frame kept as bad data.
bool JpegHoldsImage(const Frame& frame) {
  if (frame.jpeg.empty() || frame.status != FrameStatus::kOk) return false;
  StatusOr<ImageHeaderSize> size = ReadImageHeaderSize(frame.jpeg);
  if (!size.ok()) return false;
  const int64_t w = frame.image.width, h = frame.image.height;
  return (size->width == w && size->height == h) || (size->width == h && size->height == w);
}

// The manifest's view of the recording, before any file is written (sizes and checksums of
// PNG files are filled in as they are encoded).
StatusOr<Manifest> PlanManifest(const Recording& recording) {
  if (recording.frames.kind != recording.source.kind) {
    return InvalidArgumentError("frames.kind " + std::string(FrameSetKindName(recording.frames.kind)) +
                                " differs from source.kind " + std::string(FrameSetKindName(recording.source.kind)));
  }
  Manifest manifest;
  manifest.created_by = recording.created_by;
  manifest.created_at = recording.created_at.empty() ? capture::UtcNowIso8601() : recording.created_at;
  if (!capture::IsUtcIso8601(manifest.created_at)) {
    return InvalidArgumentError("created_at: '" + manifest.created_at + "' is not UTC ISO 8601 (YYYY-MM-DDTHH:MM:SSZ)");
  }
  manifest.source = recording.source;
  manifest.capture_id = recording.frames.capture_id;
  for (size_t i = 0; i < recording.frames.frames.size(); ++i) {
    const Frame& frame = recording.frames.frames[i];
    if (frame.status == FrameStatus::kOk) {
      if (Status valid = frame.image.Validate(); !valid.ok()) {
        return InvalidArgumentError("frames[" + std::to_string(i) + "]: status ok but " + valid.message());
      }
    }
    FrameEntry entry;
    entry.pixel_format = frame.image.format;
    entry.width = frame.image.width;
    entry.height = frame.image.height;
    entry.sequence = frame.sequence;
    entry.timestamp_ns = frame.timestamp_ns;
    entry.status = frame.status;
    entry.status_detail = frame.status_detail;
    entry.focal_length_px = frame.focal_length_px;
    entry.focal_length_source = frame.focal_length_source;
    if (!frame.image.bytes.empty()) {
      const capture::FrameFileType type = capture::ChooseFrameFileType(frame.image, JpegHoldsImage(frame));
      entry.file = capture::FrameFileName(i, capture::FrameFileExtension(type));
      entry.sha256 = std::string(64, '0');  // placeholder until the file is encoded
      entry.bytes = type == capture::FrameFileType::kRaw    ? frame.image.bytes.size()
                    : type == capture::FrameFileType::kJpeg ? frame.jpeg.size()
                                                            : 0;
    }
    manifest.frames.push_back(std::move(entry));
  }
  // The reader's own rules: a writer never leaves what the reader would reject.
  PX_RETURN_IF_ERROR(capture::ValidateManifest(manifest));
  return manifest;
}

// Reads, checks and decodes frame file `index` (a JPEG's own bytes into `jpeg`); errors name the file
// and the manifest field.
StatusOr<std::vector<uint8_t>> LoadFrameFile(const fs::path& dir,
                                             const FrameEntry& entry,
                                             size_t index,
                                             std::vector<uint8_t>* jpeg) {
  const fs::path path = dir / *entry.file;
  const std::string field = "manifest.json frames[" + std::to_string(index) + "]";
  StatusOr<std::vector<uint8_t>> file = ReadFileBytes(path, kMaxFrameFileBytes);
  if (!file.ok()) {
    if (file.status().code() == StatusCode::kNotFound) {
      return DataLossError(path.string() + ": missing (" + field + ".file)");
    }
    return file.status().WithContext(field);
  }
  if (file->size() != entry.bytes) {
    return DataLossError(path.string() + ": " + (file->size() < entry.bytes ? "truncated: " : "") + "has " +
                         std::to_string(file->size()) + " bytes, " + field + ".bytes says " +
                         std::to_string(entry.bytes));
  }
  const std::string sha256 = capture::Sha256Hex(*file);
  if (sha256 != *entry.sha256) {
    return DataLossError(path.string() + ": garbled: SHA-256 is " + sha256 + ", " + field + ".sha256 says " +
                         *entry.sha256);
  }
  PX_ASSIGN_OR_RETURN(capture::FrameFileType type, capture::FrameFileTypeOf(*entry.file));
  if (type == capture::FrameFileType::kRaw) return std::move(file).value();
  StatusOr<std::vector<uint8_t>> decoded =
      type == capture::FrameFileType::kJpeg
          ? capture::DecodeJpegFrame(*file, entry.width, entry.height)
          : capture::DecodePngFrame(*file, entry.pixel_format, entry.width, entry.height);
  if (!decoded.ok()) {
    return Status(decoded.status().code(), path.string() + ": " + decoded.status().message() + " (" + field + ")");
  }
  if (type == capture::FrameFileType::kJpeg) *jpeg = std::move(file).value();
  return decoded;
}

}  // namespace

Status WriteRecording(const fs::path& dir, const Recording& recording) { return WriteRecording(dir, recording, {}); }

Status WriteRecording(const fs::path& dir, const Recording& recording, const BeforeCommitHook& before_commit) {
  const auto start = std::chrono::steady_clock::now();
  StatusOr<Manifest> planned = PlanManifest(recording);
  if (!planned.ok()) return planned.status().WithContext("recording for " + dir.string());
  Manifest manifest = std::move(planned).value();

  WriteCleanup cleanup(dir);
  PX_RETURN_IF_ERROR(PrepareFolder(dir, &cleanup));

  auto commit = [&](const fs::path& path, std::span<const uint8_t> bytes) {
    cleanup.AddFile(path);
    std::function<Status()> hook;
    if (before_commit) hook = [&] { return before_commit(path); };
    return WriteFileAtomically(path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()), hook);
  };

  uint64_t total_bytes = 0;
  for (size_t i = 0; i < manifest.frames.size(); ++i) {
    FrameEntry& entry = manifest.frames[i];
    if (!entry.file) continue;
    const Frame& frame = recording.frames.frames[i];
    PX_ASSIGN_OR_RETURN(capture::FrameFileType type, capture::FrameFileTypeOf(*entry.file));
    std::vector<uint8_t> encoded;
    if (type != capture::FrameFileType::kJpeg) {
      StatusOr<std::vector<uint8_t>> made = capture::EncodeFrameFile(frame.image, type);
      if (!made.ok()) return made.status().WithContext((dir / *entry.file).string());
      encoded = std::move(made).value();
    }
    const std::span<const uint8_t> bytes = type == capture::FrameFileType::kJpeg ? std::span<const uint8_t>(frame.jpeg)
                                                                                 : std::span<const uint8_t>(encoded);
    entry.bytes = bytes.size();
    entry.sha256 = capture::Sha256Hex(bytes);
    PX_RETURN_IF_ERROR(commit(dir / *entry.file, bytes));
    total_bytes += entry.bytes;
  }
  // The frames' names must be durable before the manifest that points at them.
  PX_RETURN_IF_ERROR(FsyncDir(dir));

  const std::string text = capture::ManifestToJsonText(manifest);
  const fs::path manifest_path = dir / capture::kManifestFileName;
  PX_RETURN_IF_ERROR(commit(manifest_path, std::span(reinterpret_cast<const uint8_t*>(text.data()), text.size())));
  PX_RETURN_IF_ERROR(FsyncDir(dir));
  const fs::path parent = dir.has_parent_path() ? dir.parent_path() : fs::path(".");
  PX_RETURN_IF_ERROR(FsyncDir(parent));
  cleanup.Commit();

  Logger("replay")->info("wrote recording {} ({} frames, {:.1f} MB) in {:.0f} ms",
                         dir.string(),
                         manifest.frames.size(),
                         static_cast<double>(total_bytes + text.size()) / 1e6,
                         MillisecondsSince(start));
  return OkStatus();
}

StatusOr<Recording> ReadRecording(const fs::path& dir) {
  const auto start = std::chrono::steady_clock::now();
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return NotFoundError(dir.string() + ": no such recording folder");
  const fs::path manifest_path = dir / capture::kManifestFileName;
  StatusOr<std::vector<uint8_t>> text = ReadFileBytes(manifest_path, kMaxManifestBytes);
  if (!text.ok()) {
    if (text.status().code() == StatusCode::kNotFound) {
      return NotFoundError(manifest_path.string() + ": missing; not a recording, or its write did not finish");
    }
    return text.status();
  }
  PX_ASSIGN_OR_RETURN(nlohmann::json j, json::Parse(std::string(text->begin(), text->end()), manifest_path.string()));
  StatusOr<Manifest> parsed = capture::ManifestFromJson(j);
  if (!parsed.ok()) return parsed.status().WithContext(manifest_path.string());
  const Manifest& manifest = *parsed;

  Recording recording;
  recording.source = manifest.source;
  recording.created_by = manifest.created_by;
  recording.created_at = manifest.created_at;
  recording.frames.kind = manifest.source.kind;
  recording.frames.capture_id = manifest.capture_id;
  uint64_t total_bytes = text->size();
  for (size_t i = 0; i < manifest.frames.size(); ++i) {
    const FrameEntry& entry = manifest.frames[i];
    Frame frame;
    frame.image.format = entry.pixel_format;
    frame.image.width = entry.width;
    frame.image.height = entry.height;
    frame.sequence = entry.sequence;
    frame.timestamp_ns = entry.timestamp_ns;
    frame.status = entry.status;
    frame.status_detail = entry.status_detail;
    frame.focal_length_px = entry.focal_length_px;
    frame.focal_length_source = entry.focal_length_source;
    if (entry.file) {
      PX_ASSIGN_OR_RETURN(frame.image.bytes, LoadFrameFile(dir, entry, i, &frame.jpeg));
      total_bytes += entry.bytes;
    }
    recording.frames.frames.push_back(std::move(frame));
  }
  Logger("replay")->debug("read recording {} ({} frames, {:.1f} MB) in {:.0f} ms",
                          dir.string(),
                          recording.frames.frames.size(),
                          static_cast<double>(total_bytes) / 1e6,
                          MillisecondsSince(start));
  return recording;
}

}  // namespace px
