#include "pipeline/run/pipeline.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <future>
#include <opencv2/imgproc.hpp>
#include <optional>

#include "pipeline/calib/photometric.h"
#include "pipeline/core/log.h"
#include "pipeline/core/pixel_format.h"
#include "pipeline/core/stage_clock.h"
#include "pipeline/depth/depth_stage.h"
#include "pipeline/direct/detail_size.h"
#include "pipeline/direct/morph_framing.h"
#include "pipeline/direct/pan_zoom_2d.h"
#include "pipeline/direct/plan_camera_path.h"
#include "pipeline/direct/scene_geometry.h"
#include "pipeline/run/capture_calibration.h"
#include "pipeline/run/image_set_scale.h"
#include "pipeline/run/overlapped_frame_sink.h"
#include "pipeline/run/repeated_frames.h"

namespace px {

namespace {

// Depth that the plane sweep is sure of on less than this fraction of pixels makes a poor clip.
constexpr double kLowConfidentDepthFraction = 0.3;
// Holes inpainted over more than this fraction of a frame, on average, show.
constexpr double kHighHoleRatio = 0.05;

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
            report.path.move,
            report.path.effect,
            report.path.NumFrames(),
            d.num_subjects,
            d.detector,
            d.coverage_probes,
            d.coverage_ms,
            report.timings.back().ms);
  log->info("direct: {}", report.path.reason);
  if (report.path.output_scale > direct::kDrawAtDetailAbove) {  // below that, resampling hides it
    char text[160];
    std::snprintf(text,
                  sizeof(text),
                  "direct: the %dx%d frame is upsampled %.2fx beyond the capture's detail",
                  report.path.width,
                  report.path.height,
                  report.path.output_scale);
    log->warn("{}", text);
    warnings->push_back(text);
  }
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
Status RenderFrames(const std::vector<View>& views,
                    SceneRenderer* renderer,
                    FrameSink* sink,
                    const std::function<Status(const char*, double)>& report_progress,
                    PipelineObserver* observer,
                    double framing_margin,
                    PipelineReport* report) {
  const auto log = Logger("pipeline");
  const StageClock::time_point start = StageClock::now();
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
  // A frame enlarged beyond the capture's detail is drawn at that detail (detail_size.h).
  const bool at_detail = path.kind == PathKind::kNovelView && path.output_scale > direct::kDrawAtDetailAbove;
  double hole_sum = 0;
  // The sink (the encoder) works on frame i on its own thread while frame i + 1 is rendered.
  constexpr int kQueuedFrames = 2;
  sink->Begin(path);
  OverlappedFrameSink overlapped(sink, kQueuedFrames);
  report->frame_coverage.clear();
  report->frame_coverage.reserve(num_frames);
  PX_RETURN_IF_ERROR(report_progress("render", 0));
  // A hold, a loop's way back or a boomerang's return shows places already drawn: up to 512 MiB
  // of them are kept (a 1080p boomerang's whole outward pass at 30 fps for 2.7 s).
  RepeatedFrames repeated(path, size_t{512} << 20);
  for (int i = 0; i < num_frames; ++i) {
    const double t = path.FrameTime(i);
    cv::Mat bgr;
    if (std::optional<DrawnFrame> drawn = repeated.Take(i)) {
      bgr = drawn->bgr;
      if (path.kind == PathKind::kNovelView) {
        hole_sum += drawn->holes.hole_ratio;
        report->frame_coverage.push_back(drawn->holes);
      }
    } else {
      CoverageReport holes;
      switch (path.kind) {
        case PathKind::kNovelView: {
          const VirtualCamera camera = direct::CameraAtDetail(path.FrameAt(t), path.output_scale);
          StatusOr<FrameRender> frame = renderer->Render(camera);
          if (!frame.ok()) return frame.status().WithContext("render frame " + std::to_string(i));
          if (observer != nullptr) observer->OnFrame(i, camera, *frame);
          holes = frame->holes;
          hole_sum += frame->holes.hole_ratio;
          report->frame_coverage.push_back(frame->holes);
          bgr = direct::EnlargeToOutput(frame->bgr, path.width, path.height);
          break;
        }
        case PathKind::kMorph:
          bgr = direct::CutMorphFrame(
              report->direction.morph->FrameAt(t), path, *report->direction.morph, t, framing_margin);
          break;
        case PathKind::kPanZoom2d:
          cv::warpPerspective(flat_source->image,
                              bgr,
                              direct::FlatFrameHomography(*flat_source, path.CameraAt(t), path.PoseAt(t)),
                              cv::Size(path.width, path.height),
                              cv::INTER_LINEAR,
                              cv::BORDER_REPLICATE);
          break;
      }
      repeated.Keep(i, bgr, holes);
    }
    const Status consumed = overlapped.Consume(i, bgr);
    if (!consumed.ok()) return consumed.WithContext("frame sink, before frame " + std::to_string(i));
    report->frames_rendered = i + 1;
    PX_RETURN_IF_ERROR(report_progress("render", static_cast<double>(i + 1) / num_frames));
  }
  const Status finished = overlapped.Finish();
  if (!finished.ok()) return finished.WithContext("frame sink");
  report->mean_hole_ratio = hole_sum / num_frames;
  // Rendering: the loop's time less the waits for the sink. Encoding overlaps it: the sink's own
  // time, on its thread.
  const double sink_ms = overlapped.sink_ms();
  report->timings.push_back({"render", MsSince(start) - overlapped.wait_ms()});
  report->timings.push_back({"encode", sink_ms});
  report->frames_reused = repeated.reused();
  const int drawn = std::max(1, num_frames - report->frames_reused);
  log->info(
      "render ({}): {} frames of {}x{} ({}, {} {}), {} drawn at {:.1f} ms each, {} reused, {:.2f}% holes on "
      "average; sink {:.0f} ms",
      renderer != nullptr ? std::string(renderer->BackendName()) : std::string("2d"),
      num_frames,
      path.width,
      path.height,
      PathKindName(path.kind),
      ClipStyleName(path.timing.style),
      ClipEaseName(path.timing.ease),
      num_frames - report->frames_reused,
      report->timings[report->timings.size() - 2].ms / drawn,
      report->frames_reused,
      100 * report->mean_hole_ratio,
      sink_ms);
  if (at_detail) {
    const CameraModel drawn_at = direct::CameraAtDetail(path.FrameAt(0), path.output_scale).camera;
    log->info("render: frames drawn at the capture's detail, {}x{}, and enlarged {:.2f}x",
              drawn_at.width,
              drawn_at.height,
              path.output_scale);
  }
  if (report->mean_hole_ratio > kHighHoleRatio) {
    char text[160];
    std::snprintf(text,
                  sizeof(text),
                  "render: %.1f%% of each frame on average was inpainted (no source saw it)",
                  100 * report->mean_hole_ratio);
    report->warnings.push_back(text);
    log->warn("{}", text);
  }
  return OkStatus();
}

// An image set that cannot be calibrated: its usable images become views without poses or
// depth, and the direction stage morphs between two of them (or pans over one); a lattice frame
// whose lattice cannot be found or posed is one such image.
// The views' exposure, colour cast and vignetting brought to views[reference]'s. A failure
// leaves the views as they were: it costs seams, never the clip.
void EqualiseViews(const calib::PhotometricOptions& options,
                   int reference,
                   std::vector<View>* views,
                   PipelineReport* report) {
  if (!options.enabled || views->size() < 2) return;
  const auto log = Logger("calib");
  StatusOr<calib::PhotometricReport> equalised = calib::EqualisePhotometry(views, reference, options);
  if (!equalised.ok()) {
    report->warnings.push_back("calib: photometric equalisation skipped: " + equalised.status().message());
    log->warn("{}", report->warnings.back());
    return;
  }
  report->photometric = equalised->Summary();
  log->info("photometric: {}", report->photometric);
}

StatusOr<PipelineReport> RunUncalibrated(const FrameSet& capture,
                                         const Status& why,
                                         const PipelineOptions& options,
                                         FrameSink* sink,
                                         const std::function<Status(const char*, double)>& report_progress,
                                         PipelineReport report) {
  const auto log = Logger("pipeline");
  StageClock::time_point start = StageClock::now();
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
  if (views.empty())
    return FailedPreconditionError("capture " + std::to_string(capture.capture_id) + ": no usable image; " +
                                   why.message());
  report.num_views = static_cast<int>(views.size());
  EqualiseViews(options.photometric, static_cast<int>(views.size() / 2), &views, &report);
  report.timings.push_back({"decode", MsSince(start)});
  const std::string reason = std::string(capture.kind == FrameSetKind::kImageSet ? "image set" : "lattice frame") +
                             " without calibration (" + why.message() + ")";
  report.warnings.push_back(reason);
  log->warn("{}: morphing instead", reason);

  PX_RETURN_IF_ERROR(report_progress("direct", 0));
  start = StageClock::now();
  DirectionContext direction;
  direction.depth_trusted = false;
  direction.distrust_reason = "no calibration";
  direction.face_detector = options.face_detector.get();
  StatusOr<CameraPath> path = PlanCameraPath(views, {}, options.direct, direction, &report.direction);
  if (!path.ok()) return path.status().WithContext("direct");
  report.path = *path;
  report.timings.push_back({"direct", MsSince(start)});
  LogDirection(report, &report.warnings);
  PX_RETURN_IF_ERROR(
      RenderFrames(views, nullptr, sink, report_progress, options.observer, options.direct.framing_margin, &report));
  return report;
}
}  // namespace

Status PipelineOptions::Validate() const {
  PX_RETURN_IF_ERROR(calib.Validate());
  PX_RETURN_IF_ERROR(refinement.Validate().WithContext("pipeline.refinement"));
  PX_RETURN_IF_ERROR(sfm.Validate().WithContext("pipeline.sfm"));
  PX_RETURN_IF_ERROR(lattice.Validate().WithContext("pipeline.lattice"));
  PX_RETURN_IF_ERROR(depth.Validate());
  PX_RETURN_IF_ERROR(direct.Validate());
  PX_RETURN_IF_ERROR(render.Validate());
  PX_RETURN_IF_ERROR(render_backend.Validate());
  if (num_threads < 0 || num_threads > 256) {
    return InvalidArgumentError("pipeline.num_threads: " + std::to_string(num_threads) + " is outside [0, 256]");
  }
  if (image_set_max_side_px != 0 && (image_set_max_side_px < 64 || image_set_max_side_px > 16384)) {
    return InvalidArgumentError("pipeline.image_set_max_side_px: " + std::to_string(image_set_max_side_px) +
                                " is neither 0 (full size) nor in [64, 16384]");
  }
  return OkStatus();
}

StatusOr<std::vector<View>> MakeViewsFromCapture(const FrameSet& capture,
                                                 const RigCalibration& rig,
                                                 std::vector<std::string>* warnings,
                                                 const CalibOptions& calib,
                                                 const calib::RigRefinementOptions& refinement,
                                                 const calib::SfmOptions& sfm) {
  std::vector<std::string> ignored;
  std::vector<StageTiming> timings;
  PX_RETURN_IF_ERROR(calib.Validate());
  PX_RETURN_IF_ERROR(refinement.Validate().WithContext("refinement"));
  PX_RETURN_IF_ERROR(sfm.Validate().WithContext("sfm"));
  PX_ASSIGN_OR_RETURN(
      CalibratedViews out,
      CalibrateCapture(capture, rig, calib, refinement, sfm, warnings != nullptr ? warnings : &ignored, &timings));
  return std::move(out.views);
}

namespace {

// The progress callback as the stages call it: CANCELLED, naming the stage, when it says stop.
std::function<Status(const char*, double)> StageReporter(const ProgressCallback& progress) {
  return [progress](const char* stage, double fraction) -> Status {
    if (progress && !progress(stage, fraction))
      return CancelledError(std::string("pipeline cancelled during ") + stage);
    return OkStatus();
  };
}

// What stages 1 to 3 leave for direction and rendering.
struct SceneStages {
  std::vector<View> views;
  std::vector<DepthMap> depth_maps;
  std::vector<LayeredDepthView> layers;
  DirectionContext direction;  // the calibration's and depth's verdicts (scale, trust)
};

// Stages 1 to 3 (lattice, calibration, photometric equalisation, depth), views that match none of
// the others dropped. A capture that cannot be calibrated leaves its reason in `*uncalibrated`
// (and an OK empty result) for the caller's fallback. `on_calibrated`, when set, sees the views
// before depth (face detection starts there); `centre_faces` is waited for when the depth stage
// changes OpenCV's thread count.
StatusOr<SceneStages> RunSceneStages(const FrameSet& capture,
                                     const RigCalibration& rig,
                                     const PipelineOptions& options,
                                     const std::function<Status(const char*, double)>& report_progress,
                                     PipelineReport* report_out,
                                     Status* uncalibrated,
                                     const std::function<void(const std::vector<View>&)>& on_calibrated,
                                     std::future<direct::DetectedFaces>* centre_faces) {
  const auto log = Logger("pipeline");
  PipelineReport& report = *report_out;
  SceneStages scene;

  // Stages 1 and 2: lattice and calibrated views.
  PX_RETURN_IF_ERROR(report_progress("lattice", 0));
  StatusOr<CalibratedViews> made = CalibrateCapture(
      capture, rig, options.calib, options.refinement, options.sfm, &report.warnings, &report.timings, options.lattice);
  const bool blind_lattice = capture.kind == FrameSetKind::kLatticeFrame && rig.lattice.rows == 0;
  if (!made.ok() && (capture.kind == FrameSetKind::kImageSet || blind_lattice) &&
      (made.status().code() == StatusCode::kUnimplemented || made.status().code() == StatusCode::kFailedPrecondition)) {
    *uncalibrated = made.status();
    return scene;
  }
  if (!made.ok()) return made.status();
  CalibratedViews calibrated = std::move(made).value();
  std::vector<View>& views = scene.views;
  views = std::move(calibrated.views);
  report.num_views = static_cast<int>(views.size());
  report.calibration = calibrated.calibration;
  report.calibration_summary = calibrated.summary;
  log->info("lattice: {} views of {}x{} in {:.0f} ms, calib in {:.0f} ms",
            views.size(),
            views.front().camera.width,
            views.front().camera.height,
            report.timings[0].ms,
            report.timings[1].ms);
  EqualiseViews(options.photometric, direct::CentreViewIndex(views), &views, &report);
  PX_RETURN_IF_ERROR(report_progress("calib", 1));
  if (on_calibrated) on_calibrated(views);

  // Stage 3: depth.
  StageClock::time_point start = StageClock::now();
  DepthOptions depth_options = options.depth.WithDefaultDepthRange(calibrated.depth_min_m, calibrated.depth_max_m);
  if (depth_options.num_threads == 0) depth_options.num_threads = options.num_threads;
  // A depth stage with its own OpenCV worker count changes the process-wide pool, which would pull
  // it from under the face detection running beside it (a crash in TBB): detection finishes first.
  if (depth_options.num_threads > 0 && depth_options.num_threads != cv::getNumThreads() && centre_faces != nullptr &&
      centre_faces->valid()) {
    centre_faces->wait();
  }
  bool cancelled = false;
  StatusOr<DepthStageResult> depth = ComputeLayeredDepth(views, depth_options, [&](double fraction) {
    cancelled = !report_progress("depth", fraction).ok();
    return !cancelled;
  });
  if (cancelled) return CancelledError("pipeline cancelled during depth");
  if (!depth.ok()) return depth.status().WithContext("depth");
  report.timings.push_back({"depth", MsSince(start)});
  report.depth = depth->report;
  for (const std::string& warning : depth->report.warnings) report.warnings.push_back(warning);
  DirectionContext& direction = scene.direction;
  direction.metric_scale = calibrated.metric_scale;
  {
    const double fraction = depth->report.confident_fraction;
    const double confirmed = depth->report.consistent_fraction;
    log->info("depth: {} layered views, {:.0f} to {:.2f} m, {:.0f}% confident, {:.0f}% confirmed, in {:.0f} ms",
              depth->maps.size(),
              depth_options.min_depth_m,
              depth_options.max_depth_m,
              100 * fraction,
              100 * confirmed,
              report.timings.back().ms);
    if (fraction < kLowConfidentDepthFraction) {
      char text[160];
      std::snprintf(text,
                    sizeof(text),
                    "depth: only %.0f%% of pixels have confident depth (textureless or blurred scene?)",
                    100 * fraction);
      report.warnings.push_back(text);
      log->warn("{}", text);
    }
    // The views' depths must agree with each other (a subject that moved, poses that are off, do
    // not), and enough of them must be confident to hold a move.
    char text[200] = "";
    if (confirmed < options.direct.min_consistent_fraction) {
      std::snprintf(text,
                    sizeof(text),
                    "another view confirms %.0f%% of the depth, want %.0f%%",
                    100 * confirmed,
                    100 * options.direct.min_consistent_fraction);
    } else if (fraction < options.direct.min_confident_fraction) {
      std::snprintf(text,
                    sizeof(text),
                    "%.0f%% of the depth is confident, want %.0f%%",
                    100 * fraction,
                    100 * options.direct.min_confident_fraction);
    }
    if (text[0] != '\0') {
      direction.depth_trusted = false;
      direction.distrust_reason = text;
    }
  }
  // Views that match none of the others (a lens that saw another scene, a black or saturated
  // frame) would paint wrong colour at wrong depth: drop them while two views remain.
  std::vector<DepthMap>& depth_maps = scene.depth_maps;
  std::vector<LayeredDepthView>& layers = scene.layers;
  depth_maps = std::move(depth->maps);
  layers = std::move(depth->layered);
  if (!depth->report.disagreeing_views.empty() && views.size() - depth->report.disagreeing_views.size() >= 2) {
    std::vector<View> kept_views;
    std::vector<DepthMap> kept_maps;
    std::vector<LayeredDepthView> kept_layers;
    for (size_t i = 0; i < views.size(); ++i) {
      const auto& bad = depth->report.disagreeing_views;
      if (std::find(bad.begin(), bad.end(), views[i].id) != bad.end()) continue;
      kept_views.push_back(std::move(views[i]));
      kept_maps.push_back(std::move(depth_maps[i]));
      kept_layers.push_back(std::move(layers[i]));
    }
    const std::string text = "depth: dropped " + std::to_string(views.size() - kept_views.size()) +
                             " view(s) that match none of the others before rendering";
    report.warnings.push_back(text);
    log->warn("{}", text);
    views = std::move(kept_views);
    depth_maps = std::move(kept_maps);
    layers = std::move(kept_layers);
    report.num_views = static_cast<int>(views.size());
  }

  return scene;
}

}  // namespace

StatusOr<PipelineScene> BuildPipelineScene(const FrameSet& shot,
                                           const RigCalibration& shot_rig,
                                           const PipelineOptions& options,
                                           const ProgressCallback& progress) {
  PX_RETURN_IF_ERROR(options.Validate());
  const std::optional<WorkingImageSet> working = ImageSetAtWorkingSize(options.image_set_max_side_px, shot, shot_rig);
  const ThreadCountScope threads(options.num_threads);
  PipelineScene scene;
  Status uncalibrated;
  PX_ASSIGN_OR_RETURN(SceneStages stages,
                      RunSceneStages(working ? working->capture : shot,
                                     working ? working->rig : shot_rig,
                                     options,
                                     StageReporter(progress),
                                     &scene.report,
                                     &uncalibrated,
                                     {},
                                     nullptr));
  if (!uncalibrated.ok()) {
    return FailedPreconditionError("the capture could not be calibrated, so it has no 3D scene: " +
                                   uncalibrated.message());
  }
  scene.views = std::move(stages.views);
  scene.depth_maps = std::move(stages.depth_maps);
  scene.layers = std::move(stages.layers);
  return scene;
}

StatusOr<PipelineReport> RunPipeline(const FrameSet& shot,
                                     const RigCalibration& shot_rig,
                                     const PipelineOptions& options,
                                     FrameSink* sink,
                                     const ProgressCallback& progress) {
  PX_RETURN_IF_ERROR(options.Validate());
  if (sink == nullptr) return InvalidArgumentError("pipeline: no frame sink");
  const auto log = Logger("pipeline");
  // Hand-held photos at a working size (image_set_scale.h); a lattice frame as it is.
  const std::optional<WorkingImageSet> working = ImageSetAtWorkingSize(options.image_set_max_side_px, shot, shot_rig);
  if (working) log->info("{}", working->note);
  const FrameSet& capture = working ? working->capture : shot;
  const RigCalibration& rig = working ? working->rig : shot_rig;
  const ThreadCountScope threads(options.num_threads);
  const auto report_progress = StageReporter(progress);
  PipelineReport report;

  // Face detection needs only the centre view's image: it runs beside the depth stage, so the
  // direction stage after depth only places the faces it found.
  std::future<direct::DetectedFaces> centre_faces;
  auto start_face_detection = [&](const std::vector<View>& views) {
    if (options.face_detector != nullptr && options.direct.faces.enabled && options.direct.subject_boxes_px.empty()) {
      const View& centre = views[direct::CentreViewIndex(views)];
      // The image is shared (reference-counted), not borrowed: `views` may change meanwhile.
      centre_faces = std::async(std::launch::async, [image = centre.image, id = centre.id, &options] {
        return direct::DetectFaces(image, id, *options.face_detector, options.direct.faces);
      });
    }
  };
  Status uncalibrated;
  PX_ASSIGN_OR_RETURN(
      SceneStages scene,
      RunSceneStages(
          capture, rig, options, report_progress, &report, &uncalibrated, start_face_detection, &centre_faces));
  if (!uncalibrated.ok()) {
    // Never fail the button: images that cannot be calibrated still morph (paper 4.5); a photo
    // whose lattice cannot be found or posed gets a pan and zoom over the whole of it.
    return RunUncalibrated(capture, uncalibrated, options, sink, report_progress, std::move(report));
  }
  std::vector<View>& views = scene.views;
  std::vector<DepthMap>& depth_maps = scene.depth_maps;
  std::vector<LayeredDepthView>& layers = scene.layers;
  DirectionContext& direction = scene.direction;
  StageClock::time_point start;

  if (options.observer != nullptr) options.observer->OnScene(views, depth_maps);

  // Stage 4: the camera path, its viewpoints checked against what the renderer can cover.
  PX_RETURN_IF_ERROR(report_progress("direct", 0));
  start = StageClock::now();
  PX_ASSIGN_OR_RETURN(std::unique_ptr<render::gl::BackendSceneRenderer> renderer,
                      render::gl::BackendSceneRenderer::Create(views, layers, options.render, options.render_backend));
  report.render_backend = std::string(renderer->BackendName());
  report.render_backend_reason = renderer->reason();
  for (const std::string& warning : renderer->warnings()) report.warnings.push_back("render: " + warning);
  direction.coverage = [&renderer](const CameraModel& camera, const Rigid3& cam_from_world) {
    return renderer->Coverage(camera, cam_from_world);
  };
  // The CPU renderer's Coverage may run on several threads at once; GL's may not.
  direction.coverage_concurrent = renderer->BackendName() == "cpu";
  direction.face_detector = options.face_detector.get();
  direction.shot = options.shot.get();
  std::optional<direct::DetectedFaces> faces_found;
  if (centre_faces.valid()) faces_found = centre_faces.get();
  direction.centre_faces = faces_found ? &*faces_found : nullptr;
  StatusOr<CameraPath> path = PlanCameraPath(views, depth_maps, options.direct, direction, &report.direction);
  if (!path.ok()) return path.status().WithContext("direct");
  report.path = *path;
  report.timings.push_back({"direct", MsSince(start)});
  LogDirection(report, &report.warnings);
  PX_RETURN_IF_ERROR(report_progress("direct", 1));

  // Stage 5: render every frame and hand it on.
  PX_RETURN_IF_ERROR(RenderFrames(
      views, renderer.get(), sink, report_progress, options.observer, options.direct.framing_margin, &report));
  if (renderer->cpu_fallback_frames() > 0) {
    report.warnings.push_back("render: " + std::to_string(renderer->cpu_fallback_frames()) +
                              " frame(s) drawn on the cpu, " + report.render_backend +
                              " failed on them: " + renderer->cpu_fallback_reason());
  }
  return report;
}

}  // namespace px
