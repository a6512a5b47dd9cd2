#include "device/clip_job.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <system_error>

#include "capture/recording.h"
#include "device/storage/job_journal.h"
#include "device/storage/storage_layout.h"
#include "pipeline/core/log.h"
#include "pipeline/core/stage_clock.h"
#include "pipeline/direct/camera_path.h"
#include "pipeline/direct/shot_file.h"
#include "pipeline/io/durable_file.h"

namespace px::device {
namespace {

namespace fs = std::filesystem;

// Streams rendered frames into a ClipWriter opened on the first frame (its size is the
// pipeline's choice: the clip has the rendered frames' size), timing the encoder apart from
// rendering. On the way it keeps the poster frame and writes the small looping preview.
class ClipSink final : public FrameSink {
 public:
  ClipSink(fs::path path, clip::ClipOptions options, fs::path preview_path)
      : path_(std::move(path)), options_(std::move(options)), preview_path_(std::move(preview_path)) {}

  // The poster is the move's far end (the first frame at its largest path time): the close-up
  // of a move onto a subject, the widest parallax of an establishing move.
  void Begin(const CameraPath& path) override {
    double far_end = -1;
    for (int i = 0; i < path.NumFrames(); ++i) {
      if (path.FrameTime(i) > far_end) {
        far_end = path.FrameTime(i);
        poster_index_ = i;
      }
    }
    preview_every_ = std::max(1, static_cast<int>(std::lround(options_.fps / kPreviewFps)));
  }

  Status Consume(int index, const cv::Mat& bgr) override {
    const auto start = StageClock::now();
    if (!writer_) {
      PX_ASSIGN_OR_RETURN(writer_, clip::OpenClipWriter(path_, bgr.cols, bgr.rows, options_));
      width_ = writer_->StoredWidth();
      height_ = writer_->StoredHeight();
    }
    Status written = writer_->Write(bgr);
    if (written.ok() && index == poster_index_) poster_ = bgr.clone();
    if (written.ok() && index % preview_every_ == 0) written = WritePreview(bgr);
    encode_ms_ += MsSince(start);
    if (!written.ok()) return written.WithContext("frame " + std::to_string(index));
    return OkStatus();
  }

  Status Finish() {
    if (!writer_) return InternalError("the pipeline rendered no frames");
    const auto start = StageClock::now();
    Status finished = writer_->Finish();
    if (finished.ok() && preview_) finished = preview_->Finish().WithContext(preview_path_.string());
    encode_ms_ += MsSince(start);
    return finished;
  }

  int frames() const { return writer_ ? writer_->FramesWritten() : 0; }
  int width() const { return width_; }
  int height() const { return height_; }
  double encode_ms() const { return encode_ms_; }
  const cv::Mat& poster() const { return poster_; }

 private:
  static constexpr double kPreviewFps = 10;     // a gallery's thumbnail needs no more
  static constexpr int kPreviewLongSide = 320;  // pixels: with quality 60, well under 500 KB

  Status WritePreview(const cv::Mat& bgr) {
    const double scale = std::min(1.0, static_cast<double>(kPreviewLongSide) / std::max(bgr.cols, bgr.rows));
    cv::Mat small;
    cv::resize(bgr, small, cv::Size(), scale, scale, cv::INTER_AREA);
    if (!preview_) {
      clip::ClipOptions preview;
      preview.format = clip::ClipFormat::kWebp;
      preview.fps = options_.fps / preview_every_;
      preview.webp_quality = 60;
      PX_ASSIGN_OR_RETURN(preview_, clip::OpenClipWriter(preview_path_, small.cols, small.rows, preview));
    }
    return preview_->Write(small).WithContext("preview");
  }

  fs::path path_;
  clip::ClipOptions options_;
  fs::path preview_path_;
  std::unique_ptr<clip::ClipWriter> writer_;
  std::unique_ptr<clip::ClipWriter> preview_;
  int poster_index_ = 0;
  int preview_every_ = 1;
  cv::Mat poster_;
  int width_ = 0;
  int height_ = 0;
  double encode_ms_ = 0;
};

// Removes a file or folder on scope exit unless released (the temporary clip of a failed job).
class RemoveOnExit {
 public:
  explicit RemoveOnExit(fs::path path) : path_(std::move(path)) {}
  ~RemoveOnExit() {
    if (!path_.empty()) {
      std::error_code ec;
      fs::remove_all(path_, ec);
    }
  }
  RemoveOnExit(const RemoveOnExit&) = delete;
  RemoveOnExit& operator=(const RemoveOnExit&) = delete;
  void Release() { path_.clear(); }

 private:
  fs::path path_;
};

// Bytes of a file, or of every file under a folder (a PNG clip).
uint64_t BytesOf(const fs::path& path) {
  std::error_code ec;
  if (!fs::is_directory(path, ec)) return fs::file_size(path, ec);
  uint64_t total = 0;
  for (fs::recursive_directory_iterator it(path, ec), end; !ec && it != end; it.increment(ec)) {
    std::error_code size_ec;
    if (it->is_regular_file(size_ec)) total += it->file_size(size_ec);
  }
  return total;
}

// Puts the finished temporary in place. A file replaces an older clip of the same name
// atomically; a folder cannot replace a non-empty folder, so an older one is moved aside first
// and removed once the new one is in place.
Status PutInPlace(const fs::path& temp, const fs::path& clip_path) {
  std::error_code ec;
  if (!fs::is_directory(temp, ec) || !fs::exists(clip_path, ec)) return RenameDurably(temp, clip_path);
  const fs::path old = TemporaryPathFor(clip_path);
  PX_RETURN_IF_ERROR(RenameDurably(clip_path, old));
  PX_RETURN_IF_ERROR(RenameDurably(temp, clip_path));
  fs::remove_all(old, ec);
  return OkStatus();
}

// Per rendered frame, before hole filling: the fraction of pixels no source covered and H(V).
nlohmann::json FrameCoverageToJson(const std::vector<CoverageReport>& frames) {
  nlohmann::json out = nlohmann::json::array();
  for (const CoverageReport& frame : frames) {
    out.push_back({{"hole_ratio", frame.hole_ratio}, {"hole_score", frame.hole_score}});
  }
  return out;
}

}  // namespace

fs::path ClipPathForFormat(const fs::path& path, clip::ClipFormat format) {
  fs::path with_format = path;
  with_format.replace_extension(clip::ClipFormatExtension(format));
  return with_format;
}

Status ClipJobOptions::Validate() const {
  PX_RETURN_IF_ERROR(pipeline.Validate());
  clip::ClipOptions effective = clip;
  effective.fps = pipeline.direct.fps;
  return effective.Validate();
}

nlohmann::json ClipJobReportToJson(const ClipJobReport& report) {
  nlohmann::json timings = nlohmann::json::object();
  for (const StageTiming& timing : report.pipeline.timings) timings[timing.stage] = timing.ms;
  return {
      {"clip", report.clip_path.string()},
      {"recording", report.recording_dir.string()},
      {"source", report.source_model},
      {"created_at", NowIso8601Utc()},
      {"format", report.format},
      {"frames", report.frames_written},
      {"width", report.width},
      {"height", report.height},
      {"fps", report.pipeline.path.fps},
      // What plays: the move's frames with a hold, a loop's way back or a boomerang's return.
      {"duration_s", report.frames_written / report.pipeline.path.fps},
      {"move_duration_s", report.pipeline.path.duration_s},
      {"bytes", report.clip_bytes},
      {"poster", report.poster_path.string()},
      {"preview", report.preview_path.string()},
      {"preview_bytes", report.preview_bytes},
      {"num_views", report.pipeline.num_views},
      {"mean_hole_ratio", report.pipeline.mean_hole_ratio},
      {"frame_coverage", FrameCoverageToJson(report.pipeline.frame_coverage)},
      {"render_backend", {{"name", report.pipeline.render_backend}, {"reason", report.pipeline.render_backend_reason}}},
      {"photometric", report.pipeline.photometric},
      {"depth", {{"light_field", report.pipeline.depth.light_field}, {"options", report.pipeline.depth.mode}}},
      {"warnings", report.pipeline.warnings},
      {"timings_ms", timings},
      {"total_ms", report.total_ms},
      {"camera_path", CameraPathToJson(report.pipeline.path)},
  };
}

RigCalibration RigCalibrationFor(const Recording& recording,
                                 const fs::path& source,
                                 PipelineOptions* pipeline_options) {
  if (recording.source.rig) return *recording.source.rig;
  if (recording.frames.kind == FrameSetKind::kLatticeFrame) {
    // No rig calibration: the pipeline finds the lattice blind and poses its tiles by structure
    // from motion, with what the source knows of the lattice.
    if (recording.source.lattice) {
      pipeline_options->lattice.rows = recording.source.lattice->rows;
      pipeline_options->lattice.cols = recording.source.lattice->cols;
      pipeline_options->lattice.orientation = recording.source.lattice->orientation;
    }
    Logger("device")->info("{}: a lattice frame without a rig calibration: its lattice is found blind ({} tiles, {})",
                           source.string(),
                           pipeline_options->lattice.rows > 0 ? std::to_string(pipeline_options->lattice.rows) + "x" +
                                                                    std::to_string(pipeline_options->lattice.cols)
                                                              : std::string("any number of"),
                           std::string(TileOrientationName(pipeline_options->lattice.orientation)));
  }
  return RigCalibration();
}

StatusOr<ClipJobReport> RunClipJob(const fs::path& recording_dir,
                                   const fs::path& clip_path,
                                   const ClipJobOptions& options,
                                   const ProgressCallback& progress) {
  const auto read_start = StageClock::now();
  std::error_code ec;
  fs::path dir = fs::absolute(recording_dir, ec);
  if (ec) dir = recording_dir;
  PX_ASSIGN_OR_RETURN(Recording recording, ReadRecording(dir));
  Logger("device")->info("clip job: read recording {} ({}, {} frame(s)) in {:.0f} ms",
                         dir.string(),
                         recording.source.model,
                         recording.frames.frames.size(),
                         MsSince(read_start));
  return RunClipJob(recording, dir, clip_path, options, progress);
}

StatusOr<ClipJobReport> RunClipJob(const Recording& recording,
                                   const fs::path& source,
                                   const fs::path& clip_path,
                                   const ClipJobOptions& options,
                                   const ProgressCallback& progress) {
  const auto start = StageClock::now();
  auto log = Logger("device");
  PX_RETURN_IF_ERROR(options.Validate());
  ClipJobReport report;
  report.recording_dir = source;
  std::error_code ec;
  report.clip_path = fs::absolute(clip_path, ec);
  if (ec) report.clip_path = clip_path;
  report.report_path = ClipReportPathFor(report.clip_path);
  report.source_model = recording.source.model;
  PipelineOptions pipeline_options = options.pipeline;
  const RigCalibration rig = RigCalibrationFor(recording, source, &pipeline_options);

  clip::ClipOptions clip_options = options.clip;
  clip_options.fps = options.pipeline.direct.fps;
  report.format = std::string(clip::ClipFormatName(clip_options.format));
  const fs::path temp = TemporaryPathFor(report.clip_path);
  RemoveOnExit remove_temp(temp);
  report.poster_path = ClipPosterPathFor(report.clip_path);
  report.preview_path = ClipPreviewPathFor(report.clip_path);
  const fs::path preview_temp = TemporaryPathFor(report.preview_path);
  RemoveOnExit remove_preview_temp(preview_temp);
  ClipSink sink(temp, clip_options, preview_temp);
  StatusOr<PipelineReport> pipeline = RunPipeline(recording.frames, rig, pipeline_options, &sink, progress);
  if (!pipeline.ok()) return pipeline.status();
  report.pipeline = std::move(pipeline).value();
  PX_RETURN_IF_ERROR(sink.Finish().WithContext(temp.string()));
  // The sink's own clock is the encoder's time; replace any "encode" figure the pipeline kept.
  std::erase_if(report.pipeline.timings, [](const StageTiming& t) { return t.stage == "encode"; });
  report.pipeline.timings.push_back({"encode", sink.encode_ms()});
  report.frames_written = sink.frames();
  report.width = sink.width();
  report.height = sink.height();

  PX_RETURN_IF_ERROR(FsyncFile(temp));
  // The last point where the job can still stop (or a crash test pause) before the clip appears.
  if (progress && !progress("encode", 1.0))
    return CancelledError("clip job cancelled before the clip was put in place");
  // Poster and preview first: a clip in place always has them beside it.
  std::vector<uchar> poster_jpeg;
  if (sink.poster().empty() || !cv::imencode(".jpg", sink.poster(), poster_jpeg, {cv::IMWRITE_JPEG_QUALITY, 90})) {
    return InternalError("the clip's poster frame could not be encoded");
  }
  PX_RETURN_IF_ERROR(WriteFileAtomically(report.poster_path, std::string(poster_jpeg.begin(), poster_jpeg.end())));
  RemoveOnExit remove_poster(report.poster_path);
  PX_RETURN_IF_ERROR(FsyncFile(preview_temp));
  PX_RETURN_IF_ERROR(RenameDurably(preview_temp, report.preview_path));
  remove_preview_temp.Release();
  RemoveOnExit remove_preview(report.preview_path);
  PX_RETURN_IF_ERROR(PutInPlace(temp, report.clip_path));
  remove_temp.Release();
  RemoveOnExit remove_clip(report.clip_path);  // until the report is beside it
  report.clip_bytes = BytesOf(report.clip_path);
  report.preview_bytes = BytesOf(report.preview_path);
  report.total_ms = MsSince(start);
  // The shot that reproduces this clip, for replaying or editing it (parallax clip --shot, the web
  // app's authoring); written before the report, which completes the clip's files.
  const fs::path shot_path = ClipShotPathFor(report.clip_path);
  PX_RETURN_IF_ERROR(
      WriteFileAtomically(shot_path, direct::ShotToJson(direct::ShotFromPath(report.pipeline.path)).dump(2) + "\n"));
  RemoveOnExit remove_shot(shot_path);
  PX_RETURN_IF_ERROR(WriteFileAtomically(report.report_path, ClipJobReportToJson(report).dump(2) + "\n"));
  remove_clip.Release();
  remove_poster.Release();
  remove_preview.Release();
  remove_shot.Release();
  log->info("clip job: wrote {} ({} {} frames {}x{}, {:.2f} MB, encode {:.0f} ms) in {:.0f} ms",
            report.clip_path.string(),
            report.format,
            report.frames_written,
            report.width,
            report.height,
            static_cast<double>(report.clip_bytes) / 1e6,
            sink.encode_ms(),
            report.total_ms);
  return report;
}

}  // namespace px::device
