#include "pipeline/run/pipeline.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>

#include <opencv2/imgproc.hpp>

#include "pipeline/calib/make_views.h"
#include "pipeline/core/log.h"
#include "pipeline/core/pixel_format.h"
#include "pipeline/depth/plane_sweep.h"
#include "pipeline/direct/plan_camera_path.h"
#include "pipeline/lattice/split_lattice.h"
#include "pipeline/direct/pan_zoom_2d.h"
#include "pipeline/run/frame_salvage.h"
#include "pipeline/run/novel_view_scene_renderer.h"

namespace px {

namespace {

using Clock = std::chrono::steady_clock;

double MsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// A tile whose grey levels vary less than this (standard deviation, 8-bit levels) shows no
// scene: a covered, dead or unlit lens. Sensor noise alone exceeds it on any real image.
constexpr double kBlankTileStddev = 1.0;
// Depth that the plane sweep is sure of on less than this fraction of pixels makes a poor clip.
constexpr double kLowConfidentDepthFraction = 0.3;
// Holes inpainted over more than this fraction of a frame, on average, show.
constexpr double kHighHoleRatio = 0.05;

std::string FrameName(const FrameSet& capture, size_t index) {
  const Frame& frame = capture.frames[index];
  return "capture " + std::to_string(capture.capture_id) + " frame " + std::to_string(index) + " (sequence " +
         std::to_string(frame.sequence) + ")";
}

// The error for a lattice frame that cannot be used, by what went wrong with it.
Status UnusableFrameError(const FrameSet& capture, size_t index) {
  const Frame& frame = capture.frames[index];
  std::string message = FrameName(capture, index) + " is " + std::string(FrameStatusName(frame.status));
  if (!frame.status_detail.empty()) message += ": " + frame.status_detail;
  switch (frame.status) {
    case FrameStatus::kCorrupt:
      return DataLossError(message);
    case FrameStatus::kDropped:
      return UnavailableError(message);
    case FrameStatus::kWrongFormat:
      return InvalidArgumentError(message);
    case FrameStatus::kOk:
      break;
  }
  return InternalError(message);
}

// When no frame is ok, the one that can still honestly be used (frame_salvage.h): a frame at the
// sensor's size in another pixel format (it decodes as what it says it is), else a truncated one
// (its whole rows). Sets *bgr and *complete_rows and says so in a warning; frames.size() if none.
size_t SalvageFrame(const FrameSet& capture, const LatticeLayout& lattice, cv::Mat* bgr, int* complete_rows,
                    std::vector<std::string>* warnings) {
  for (size_t i = 0; i < capture.frames.size(); ++i) {
    const Frame& frame = capture.frames[i];
    const RawImage& image = frame.image;
    if (frame.status != FrameStatus::kWrongFormat || image.width != lattice.sensor_width ||
        image.height != lattice.sensor_height || !image.Validate().ok()) {
      continue;
    }
    StatusOr<cv::Mat> decoded = ToBgr(image);
    if (!decoded.ok()) continue;
    *bgr = *decoded;
    *complete_rows = image.height;
    warnings->push_back(FrameName(capture, i) + " came as " + std::string(PixelFormatName(image.format)) +
                        ", not as configured (" + frame.status_detail + "); used as it decodes");
    return i;
  }
  for (size_t i = 0; i < capture.frames.size(); ++i) {
    const Frame& frame = capture.frames[i];
    if (frame.status != FrameStatus::kCorrupt || frame.image.width != lattice.sensor_width ||
        frame.image.height != lattice.sensor_height) {
      continue;
    }
    StatusOr<SalvagedFrame> salvaged = SalvageTruncatedFrame(frame.image);
    if (!salvaged.ok() || salvaged->complete_rows == 0) continue;
    *bgr = salvaged->bgr;
    *complete_rows = salvaged->complete_rows;
    warnings->push_back(FrameName(capture, i) + " is truncated (" + std::to_string(salvaged->bytes_arrived) + " of " +
                        std::to_string(salvaged->bytes_expected) + " bytes): using the views in its first " +
                        std::to_string(salvaged->complete_rows) + " rows");
    return i;
  }
  return capture.frames.size();
}

// Splits the lattice frame and makes the views, timing both stages.
StatusOr<std::vector<View>> LatticeViews(const FrameSet& capture, const RigCalibration& rig,
                                         const CalibOptions& calib, std::vector<std::string>* warnings,
                                         std::vector<StageTiming>* timings) {
  if (capture.kind == FrameSetKind::kImageSet) {
    return UnimplementedError("capture " + std::to_string(capture.capture_id) + ": an image set of " +
                              std::to_string(capture.frames.size()) +
                              " images needs per-shot calibration (structure from motion); hand-held mode comes "
                              "with calibration");
  }
  if (capture.frames.empty()) {
    return InvalidArgumentError("capture " + std::to_string(capture.capture_id) + " holds no frames");
  }
  PX_RETURN_IF_ERROR(rig.Validate().WithContext("rig calibration '" + rig.rig_name + "'"));
  if (rig.lattice.rows == 0) {
    return FailedPreconditionError("rig calibration '" + rig.rig_name + "' has no lattice layout for a lattice frame");
  }

  const Clock::time_point lattice_start = Clock::now();
  size_t chosen = capture.frames.size();
  for (size_t i = 0; i < capture.frames.size(); ++i) {
    if (capture.frames[i].status == FrameStatus::kOk) {
      chosen = i;
      break;
    }
  }
  cv::Mat salvaged;                               // set when the chosen frame is not ok
  int complete_rows = rig.lattice.sensor_height;  // rows of the sensor frame that arrived whole
  if (chosen == capture.frames.size()) {
    chosen = SalvageFrame(capture, rig.lattice, &salvaged, &complete_rows, warnings);
    if (chosen == capture.frames.size()) return UnusableFrameError(capture, 0);
  }
  for (size_t i = 0; i < capture.frames.size(); ++i) {
    if (i == chosen) continue;
    warnings->push_back(FrameName(capture, i) + " skipped: a lattice capture needs one frame, used frame " +
                        std::to_string(chosen) +
                        (capture.frames[i].status == FrameStatus::kOk
                             ? ""
                             : std::string(" (this one is ") + std::string(FrameStatusName(capture.frames[i].status)) +
                                   ")"));
  }
  StatusOr<cv::Mat> sensor = salvaged.empty() ? ToBgr(capture.frames[chosen].image) : StatusOr<cv::Mat>(salvaged);
  if (!sensor.ok()) return sensor.status().WithContext(FrameName(capture, chosen));
  StatusOr<std::vector<cv::Mat>> tiles = SplitLattice(*sensor, rig.lattice);
  if (!tiles.ok()) return tiles.status().WithContext(FrameName(capture, chosen));
  timings->push_back({"lattice", MsSince(lattice_start)});

  const Clock::time_point calib_start = Clock::now();
  PX_ASSIGN_OR_RETURN(std::vector<View> views, MakeViews(*tiles, rig, calib));
  // Drop blank views: they match nothing and would only add wrong depth and colour.
  std::vector<View> usable;
  std::vector<std::string> blank;
  for (View& view : views) {
    const cv::Rect& tile = rig.lattice.tiles[view.id.value].rect;
    if (tile.br().y > complete_rows) {
      blank.push_back("view " + std::to_string(view.id.value) + " was lost: its tile (rows " + std::to_string(tile.y) +
                      ".." + std::to_string(tile.br().y - 1) + ") lies past the " + std::to_string(complete_rows) +
                      " rows that arrived");
      continue;
    }
    cv::Mat grey;
    cv::cvtColor(view.image, grey, cv::COLOR_BGR2GRAY);
    cv::Scalar mean, stddev;
    cv::meanStdDev(grey, mean, stddev);
    if (stddev[0] < kBlankTileStddev) {
      char text[160];
      std::snprintf(text, sizeof(text), "view %d is blank (grey mean %.1f, stddev %.2f): lens covered or dead",
                    view.id.value, mean[0], stddev[0]);
      blank.push_back(text);
    } else {
      usable.push_back(std::move(view));
    }
  }
  if (usable.size() < 2) {
    return FailedPreconditionError(FrameName(capture, chosen) + ": only " + std::to_string(usable.size()) + " of " +
                                   std::to_string(rig.NumViews()) + " views show the scene" +
                                   (blank.empty() ? "" : "; " + blank.front()));
  }
  for (std::string& text : blank) warnings->push_back(std::move(text) + "; dropped");
  timings->push_back({"calib", MsSince(calib_start)});
  return usable;
}

// Sets OpenCV's worker count for the run and restores it after.
class ThreadCountScope {
 public:
  explicit ThreadCountScope(int num_threads) : previous_(cv::getNumThreads()) {
    if (num_threads > 0) cv::setNumThreads(num_threads);
  }
  ~ThreadCountScope() { cv::setNumThreads(previous_); }
  ThreadCountScope(const ThreadCountScope&) = delete;
  ThreadCountScope& operator=(const ThreadCountScope&) = delete;

 private:
  int previous_;
};


// Logs the direction stage's decision and copies its fallbacks and notes into the warnings
// (they reach the clip's JSON there and in the camera path's notes).
void LogDirection(const PipelineReport& report, std::vector<std::string>* warnings) {
  const auto log = Logger("pipeline");
  const DirectionReport& d = report.direction;
  log->info("direct: {} ({}), {} frames; subjects: {} ({}); {} coverage probes in {:.0f} ms; {:.1f} ms in all",
            report.path.move, report.path.effect, report.path.NumFrames(), d.num_subjects, d.detector,
            d.coverage_probes, d.coverage_ms, report.timings.back().ms);
  log->info("direct: {}", report.path.reason);
  for (const std::string& note : report.path.notes) {
    if (d.fell_back) {
      log->warn("direct: {}", note);
    } else {
      log->info("direct: {}", note);
    }
    warnings->push_back("direct: " + note);
  }
}

// Renders every frame of report->path (novel views, a morph or a flat pan and zoom) into `sink`.
Status RenderFrames(const std::vector<View>& views, SceneRenderer* renderer, FrameSink* sink,
                    const std::function<Status(const char*, double)>& report_progress, PipelineReport* report) {
  const auto log = Logger("pipeline");
  const Clock::time_point start = Clock::now();
  const CameraPath& path = report->path;
  const View* flat_source = nullptr;
  if (path.kind == PathKind::kPanZoom2d) {
    for (const View& view : views) {
      if (view.id.value == path.source_views.front()) flat_source = &view;
    }
    if (flat_source == nullptr) {
      return InternalError("render: the pan and zoom's view " + std::to_string(path.source_views.front()) +
                           " is not among the views");
    }
  }
  if (path.kind == PathKind::kMorph && report->direction.morph == nullptr) {
    return InternalError("render: a morph path without its correspondences");
  }
  if (path.kind == PathKind::kNovelView && renderer == nullptr) {
    return InternalError("render: a novel-view path without a renderer");
  }
  const int num_frames = path.NumFrames();
  double sink_ms = 0, hole_sum = 0;
  PX_RETURN_IF_ERROR(report_progress("render", 0));
  for (int i = 0; i < num_frames; ++i) {
    const double t = path.FrameTime(i);
    cv::Mat bgr;
    switch (path.kind) {
      case PathKind::kNovelView: {
        StatusOr<FrameRender> frame = renderer->Render(path.FrameAt(t));
        if (!frame.ok()) return frame.status().WithContext("render frame " + std::to_string(i));
        hole_sum += frame->holes.hole_ratio;
        bgr = std::move(frame->bgr);
        break;
      }
      case PathKind::kMorph:
        bgr = report->direction.morph->FrameAt(t);
        break;
      case PathKind::kPanZoom2d:
        cv::warpPerspective(flat_source->image, bgr,
                            direct::FlatFrameHomography(*flat_source, path.CameraAt(t), path.PoseAt(t)),
                            cv::Size(path.width, path.height), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
        break;
    }
    const Clock::time_point sink_start = Clock::now();
    const Status consumed = sink->Consume(i, bgr);
    sink_ms += MsSince(sink_start);
    if (!consumed.ok()) return consumed.WithContext("frame sink, frame " + std::to_string(i));
    report->frames_rendered = i + 1;
    PX_RETURN_IF_ERROR(report_progress("render", static_cast<double>(i + 1) / num_frames));
  }
  report->mean_hole_ratio = hole_sum / num_frames;
  report->timings.push_back({"render", MsSince(start) - sink_ms});
  report->timings.push_back({"encode", sink_ms});
  log->info("render: {} frames of {}x{} ({}), {:.1f} ms each, {:.2f}% holes on average; sink {:.0f} ms", num_frames,
            path.width, path.height, PathKindName(path.kind),
            report->timings[report->timings.size() - 2].ms / num_frames, 100 * report->mean_hole_ratio, sink_ms);
  if (report->mean_hole_ratio > kHighHoleRatio) {
    char text[160];
    std::snprintf(text, sizeof(text), "render: %.1f%% of each frame on average was inpainted (no source saw it)",
                  100 * report->mean_hole_ratio);
    report->warnings.push_back(text);
    log->warn("{}", text);
  }
  return OkStatus();
}

// An image set that cannot be calibrated: its usable images become views without poses or
// depth, and the direction stage morphs between two of them (or pans over one).
StatusOr<PipelineReport> RunUncalibrated(const FrameSet& capture, const Status& why, const PipelineOptions& options,
                                         FrameSink* sink,
                                         const std::function<Status(const char*, double)>& report_progress,
                                         PipelineReport report) {
  const auto log = Logger("pipeline");
  Clock::time_point start = Clock::now();
  std::vector<View> views;
  for (size_t i = 0; i < capture.frames.size(); ++i) {
    const Frame& frame = capture.frames[i];
    if (frame.status != FrameStatus::kOk) {
      report.warnings.push_back(FrameName(capture, i) + " skipped: " + std::string(FrameStatusName(frame.status)));
      continue;
    }
    StatusOr<cv::Mat> bgr = ToBgr(frame.image);
    if (!bgr.ok()) {
      report.warnings.push_back(FrameName(capture, i) + " skipped: " + bgr.status().message());
      continue;
    }
    View view;
    view.id.value = static_cast<int32_t>(i);
    view.image = *bgr;
    if (!views.empty() && view.image.size() != views.front().image.size()) {
      cv::resize(view.image, view.image, views.front().image.size(), 0, 0, cv::INTER_AREA);
      report.warnings.push_back(FrameName(capture, i) + " resized to the first image's size for the morph");
    }
    // No calibration: a nominal pinhole (a 53 degree field of view) at the origin; a morph and
    // a flat pan and zoom need only the image.
    view.camera = CameraModel::Pinhole(view.image.cols, view.image.rows, std::max(view.image.cols, view.image.rows));
    views.push_back(std::move(view));
  }
  if (views.empty()) return FailedPreconditionError("capture " + std::to_string(capture.capture_id) + ": no usable image; " + why.message());
  report.num_views = static_cast<int>(views.size());
  report.timings.push_back({"decode", MsSince(start)});
  const std::string reason = "image set without calibration (" + why.message() + ")";
  report.warnings.push_back(reason);
  log->warn("{}: morphing instead", reason);

  PX_RETURN_IF_ERROR(report_progress("direct", 0));
  start = Clock::now();
  DirectionContext direction;
  direction.depth_trusted = false;
  direction.distrust_reason = "no calibration";
  direction.face_detector = options.face_detector.get();
  StatusOr<CameraPath> path = PlanCameraPath(views, {}, options.direct, direction, &report.direction);
  if (!path.ok()) return path.status().WithContext("direct");
  report.path = *path;
  report.timings.push_back({"direct", MsSince(start)});
  LogDirection(report, &report.warnings);
  PX_RETURN_IF_ERROR(RenderFrames(views, nullptr, sink, report_progress, &report));
  return report;
}
}  // namespace

Status PipelineOptions::Validate() const {
  PX_RETURN_IF_ERROR(calib.Validate());
  PX_RETURN_IF_ERROR(depth.Validate());
  PX_RETURN_IF_ERROR(direct.Validate());
  PX_RETURN_IF_ERROR(render.Validate());
  if (num_threads < 0 || num_threads > 256) {
    return InvalidArgumentError("pipeline.num_threads: " + std::to_string(num_threads) + " is outside [0, 256]");
  }
  return OkStatus();
}

StatusOr<std::vector<View>> MakeViewsFromCapture(const FrameSet& capture, const RigCalibration& rig,
                                                 std::vector<std::string>* warnings, const CalibOptions& calib) {
  std::vector<std::string> ignored;
  std::vector<StageTiming> timings;
  PX_RETURN_IF_ERROR(calib.Validate());
  return LatticeViews(capture, rig, calib, warnings != nullptr ? warnings : &ignored, &timings);
}

StatusOr<PipelineReport> RunPipeline(const FrameSet& capture, const RigCalibration& rig,
                                     const PipelineOptions& options, FrameSink* sink,
                                     const ProgressCallback& progress) {
  PX_RETURN_IF_ERROR(options.Validate());
  if (sink == nullptr) return InvalidArgumentError("pipeline: no frame sink");
  const auto log = Logger("pipeline");
  const ThreadCountScope threads(options.num_threads);
  const auto report_progress = [&](const char* stage, double fraction) -> Status {
    if (progress && !progress(stage, fraction)) return CancelledError(std::string("pipeline cancelled during ") + stage);
    return OkStatus();
  };
  PipelineReport report;

  // Stages 1 and 2: lattice and calibrated views.
  PX_RETURN_IF_ERROR(report_progress("lattice", 0));
  StatusOr<std::vector<View>> made = LatticeViews(capture, rig, options.calib, &report.warnings, &report.timings);
  if (!made.ok() && capture.kind == FrameSetKind::kImageSet &&
      (made.status().code() == StatusCode::kUnimplemented || made.status().code() == StatusCode::kFailedPrecondition)) {
    // Never fail the button: images that cannot be calibrated still morph (paper 4.5).
    return RunUncalibrated(capture, made.status(), options, sink, report_progress, std::move(report));
  }
  if (!made.ok()) return made.status();
  std::vector<View> views = std::move(made).value();
  report.num_views = static_cast<int>(views.size());
  log->info("lattice: {} views of {}x{} in {:.0f} ms, calib in {:.0f} ms", views.size(), views.front().camera.width,
            views.front().camera.height, report.timings[0].ms, report.timings[1].ms);
  PX_RETURN_IF_ERROR(report_progress("calib", 1));

  // Stage 3: depth.
  Clock::time_point start = Clock::now();
  DepthOptions depth_options = options.depth.WithDefaultDepthRange(rig.nominal_depth_min_m, rig.nominal_depth_max_m);
  if (depth_options.num_threads == 0) depth_options.num_threads = options.num_threads;
  bool cancelled = false;
  StatusOr<std::vector<DepthMap>> depths = ComputeDepth(views, depth_options, [&](double fraction) {
    cancelled = !report_progress("depth", fraction).ok();
    return !cancelled;
  });
  if (cancelled) return CancelledError("pipeline cancelled during depth");
  if (!depths.ok()) return depths.status().WithContext("depth");
  report.timings.push_back({"depth", MsSince(start)});
  DirectionContext direction;
  {
    double confident = 0, total = 0;
    for (const DepthMap& map : *depths) {
      confident += cv::countNonZero(map.confidence > 0.5);
      total += static_cast<double>(map.confidence.total());
    }
    const double fraction = total > 0 ? confident / total : 0;
    log->info("depth: {} maps, {:.0f} to {:.2f} m, {:.0f}% confident, in {:.0f} ms", depths->size(),
              depth_options.min_depth_m, depth_options.max_depth_m, 100 * fraction, report.timings.back().ms);
    if (fraction < kLowConfidentDepthFraction) {
      char text[160];
      std::snprintf(text, sizeof(text),
                    "depth: only %.0f%% of pixels have confident depth (textureless or blurred scene?)",
                    100 * fraction);
      report.warnings.push_back(text);
      log->warn("{}", text);
    }
    if (fraction < options.direct.min_confident_fraction) {
      direction.depth_trusted = false;
      char text[160];
      std::snprintf(text, sizeof(text), "%.0f%% of the depth is confident, want %.0f%%", 100 * fraction,
                    100 * options.direct.min_confident_fraction);
      direction.distrust_reason = text;
    }
  }

  // Stage 4: the camera path, its viewpoints checked against what the renderer can cover.
  PX_RETURN_IF_ERROR(report_progress("direct", 0));
  start = Clock::now();
  PX_ASSIGN_OR_RETURN(std::unique_ptr<NovelViewSceneRenderer> renderer,
                      NovelViewSceneRenderer::Create(views, *depths, options.render));
  direction.coverage = [&renderer](const CameraModel& camera, const Rigid3& cam_from_world) {
    return renderer->Coverage(camera, cam_from_world);
  };
  direction.face_detector = options.face_detector.get();
  direction.shot = options.shot.get();
  StatusOr<CameraPath> path = PlanCameraPath(views, *depths, options.direct, direction, &report.direction);
  if (!path.ok()) return path.status().WithContext("direct");
  report.path = *path;
  report.timings.push_back({"direct", MsSince(start)});
  LogDirection(report, &report.warnings);
  PX_RETURN_IF_ERROR(report_progress("direct", 1));

  // Stage 5: render every frame and hand it on.
  PX_RETURN_IF_ERROR(RenderFrames(views, renderer.get(), sink, report_progress, &report));
  return report;
}

}  // namespace px
