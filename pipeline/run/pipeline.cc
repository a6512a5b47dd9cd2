#include "pipeline/run/pipeline.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>

#include <opencv2/imgproc.hpp>

#include "pipeline/calib/incremental_sfm.h"
#include "pipeline/calib/make_views.h"
#include "pipeline/calib/rig_refinement.h"
#include "pipeline/calib/undistort_cache.h"
#include "pipeline/core/log.h"
#include "pipeline/core/pixel_format.h"
#include "pipeline/depth/depth_stage.h"
#include "pipeline/direct/pan_zoom_2d.h"
#include "pipeline/direct/plan_camera_path.h"
#include "pipeline/lattice/lattice_detector.h"
#include "pipeline/lattice/split_lattice.h"
#include "pipeline/run/frame_salvage.h"

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

// Tiles found further than this from the rig calibration's layout count as moved.
constexpr double kLatticeMovedPx = 1.5;

// The rig's layout checked against the frame: the lattice is searched near it (tens of ms) and,
// when it has moved (a knock, a re-seated lens mask), each tile keeps its calibrated size (its
// intrinsics are for that size) at the position and rotation found, with a warning. A frame whose
// lattice cannot be confirmed keeps the calibrated layout (logged: dark or blank tiles hide edges).
LatticeLayout CheckedLattice(const cv::Mat& sensor, const RigCalibration& rig, std::vector<std::string>* warnings) {
  StatusOr<LatticeDetection> found = DetectLattice(sensor, LatticeOptions(), &rig.lattice);
  if (!found.ok()) {
    Logger("pipeline")->info("lattice check inconclusive, using the calibrated layout: {}", found.status().message());
    return rig.lattice;
  }
  if (found->report.max_prior_shift_px <= kLatticeMovedPx) return rig.lattice;
  LatticeLayout moved = rig.lattice;
  for (size_t i = 0; i < moved.tiles.size(); ++i) {
    Tile& tile = moved.tiles[i];
    const cv::Point2d centre = TileCentre(found->layout.tiles[i]);
    tile.rect.x = static_cast<int>(std::lround(centre.x - 0.5 * (tile.rect.width - 1)));
    tile.rect.y = static_cast<int>(std::lround(centre.y - 0.5 * (tile.rect.height - 1)));
    tile.rotation_deg = found->layout.tiles[i].rotation_deg;
  }
  if (!moved.Validate().ok()) return rig.lattice;
  char text[240];
  std::snprintf(text, sizeof(text),
                "lattice moved: tiles found up to %.1f px from the rig calibration's layout (confidence %.2f); "
                "cut at the found positions with the calibrated intrinsics",
                found->report.max_prior_shift_px, found->report.confidence);
  warnings->push_back(text);
  return moved;
}

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

// Views with the calibration they came from and the depth range they support.
struct CalibratedViews {
  std::vector<View> views;
  double depth_min_m = 0;
  double depth_max_m = 0;
  std::string calibration;  // PipelineReport::calibration
  std::string summary;
};

// Refines the factory calibration from the tiles when enabled; the factory's otherwise or
// when refinement is not trustworthy (the reason in `warnings`).
RigCalibration RefinedRig(const std::vector<cv::Mat>& tiles, const RigCalibration& rig,
                          const calib::RigRefinementOptions& refinement, std::vector<std::string>* warnings,
                          CalibratedViews* out) {
  out->calibration = "factory";
  if (!refinement.enabled) return rig;
  const auto log = Logger("calib");
  StatusOr<calib::RigRefinementResult> refined = calib::RefineRigCalibration(tiles, rig, refinement);
  if (!refined.ok()) {
    warnings->push_back("calib: per-shot refinement failed (" + refined.status().ToString() +
                        "); the factory calibration is used");
    log->warn("{}", warnings->back());
    return rig;
  }
  const calib::RigRefinementReport& report = refined->report;
  char text[256];
  std::snprintf(text, sizeof(text),
                "%d lens pairs, %d matches, %d inliers, %d tracks, reprojection RMS %.2f -> %.2f px, max change "
                "%.3f deg, %.2f mm, focal %.2f %%, %.0f ms",
                report.num_pairs, report.num_matches, report.num_inliers, report.num_tracks, report.rms_before_px,
                report.rms_after_px, report.max_rotation_change_deg, 1000 * report.max_centre_change_m,
                100 * report.max_focal_change_relative, report.total_ms);
  out->summary = text;
  if (report.factory_fits) {
    out->calibration = "factory (confirmed by refinement)";
    log->info("calib: {}: {}", report.fallback_reason, out->summary);
    return rig;
  }
  for (const std::string& warning : report.warnings) warnings->push_back("calib: " + warning);
  if (!report.refined) {
    warnings->push_back("calib: per-shot refinement not used (" + report.fallback_reason +
                        "); the factory calibration is used");
    log->warn("{}", warnings->back());
    return rig;
  }
  out->calibration = "refined";
  log->info("calib: refined: {}", out->summary);
  return refined->rig;
}

// Views of `images` (ids `view_ids`, named `image_names` in warnings) posed by structure from
// motion; unregistered images are named in `warnings` and dropped.
StatusOr<CalibratedViews> SfmViews(const std::string& name, const std::vector<calib::SfmImage>& images,
                                   const std::vector<size_t>& view_ids, const std::vector<std::string>& image_names,
                                   const CalibOptions& calib_options, const calib::SfmOptions& sfm,
                                   std::vector<std::string>* warnings) {
  PX_ASSIGN_OR_RETURN(calib::SfmResult sfm_result, calib::RunIncrementalSfm(images, sfm));
  const calib::SfmReport& report = sfm_result.report;
  if (!report.success) {
    return FailedPreconditionError(name + ": structure from motion failed: " + report.failure);
  }
  for (const std::string& warning : report.warnings) warnings->push_back("calib: " + warning);
  CalibratedViews out;
  out.calibration = "structure from motion";
  char text[256];
  std::snprintf(text, sizeof(text), "%d of %d images registered, %d points, reprojection RMS %.2f px, focal %s%s, %.0f ms",
                report.num_registered, report.num_images, report.num_points, report.rms_px,
                report.focal_source.c_str(), report.focal_observable ? "" : " (unobservable)", report.total_ms);
  out.summary = text;
  std::vector<double> nears, fars;
  UndistortCache cache;
  for (size_t i = 0; i < images.size(); ++i) {
    const calib::SfmView& sfm_view = sfm_result.views[i];
    if (!sfm_view.registered) {
      warnings->push_back(image_names[i] + " not registered: " + sfm_view.note + "; dropped");
      continue;
    }
    PX_ASSIGN_OR_RETURN(View view, MakeView(ViewId{static_cast<int>(view_ids[i])}, images[i].image, sfm_view.camera,
                                            sfm_view.cam_from_world, calib_options, &cache));
    out.views.push_back(std::move(view));
    if (sfm_view.depth_near > 0) nears.push_back(sfm_view.depth_near);
    if (sfm_view.depth_far > 0) fars.push_back(sfm_view.depth_far);
  }
  if (out.views.size() < 2 || nears.empty()) {
    return FailedPreconditionError(name + ": structure from motion registered " + std::to_string(out.views.size()) +
                                   " images with depth; at least 2 are needed");
  }
  // Scene units (SfmOptions::median_depth): the views' near and far points, with a margin.
  out.depth_min_m = 0.8 * *std::min_element(nears.begin(), nears.end());
  out.depth_max_m = 1.25 * *std::max_element(fars.begin(), fars.end());
  Logger("calib")->info("calib: structure from motion: {}", out.summary);
  return out;
}

// An image set's views: poses and focal lengths from structure from motion. Images that
// cannot be used (bad frames, unregistered) are named in `warnings`.
StatusOr<CalibratedViews> ImageSetViews(const FrameSet& capture, const RigCalibration& rig,
                                        const CalibOptions& calib_options, const calib::SfmOptions& sfm,
                                        std::vector<std::string>* warnings, std::vector<StageTiming>* timings) {
  const std::string name = "capture " + std::to_string(capture.capture_id);
  if (capture.frames.size() < 2) {
    return FailedPreconditionError(name + ": an image set needs at least 2 images, got " +
                                std::to_string(capture.frames.size()));
  }
  const Clock::time_point start = Clock::now();
  std::vector<calib::SfmImage> images;
  std::vector<size_t> frame_of_image;
  for (size_t i = 0; i < capture.frames.size(); ++i) {
    const Frame& frame = capture.frames[i];
    StatusOr<cv::Mat> bgr = frame.status == FrameStatus::kOk ? ToBgr(frame.image) : StatusOr<cv::Mat>(
                                                                    UnusableFrameError(capture, i));
    if (!bgr.ok()) {
      warnings->push_back(FrameName(capture, i) + " skipped: " + bgr.status().ToString());
      continue;
    }
    calib::SfmImage image;
    image.image = *bgr;
    // A rig with one lens per image (a replayed, calibrated set) gives the intrinsics.
    if (rig.NumViews() == static_cast<int>(capture.frames.size())) {
      const CameraModel& lens = rig.lenses[i].camera;
      if (lens.width == bgr->cols && lens.height == bgr->rows) image.intrinsics = lens;
    }
    images.push_back(std::move(image));
    frame_of_image.push_back(i);
  }
  timings->push_back({"lattice", MsSince(start)});  // decoding, for an image set
  if (images.size() < 2) {
    return FailedPreconditionError(name + ": only " + std::to_string(images.size()) + " of " +
                                   std::to_string(capture.frames.size()) + " images are usable");
  }
  std::vector<std::string> image_names;
  for (size_t frame : frame_of_image) image_names.push_back(FrameName(capture, frame));
  const Clock::time_point calib_start = Clock::now();
  PX_ASSIGN_OR_RETURN(CalibratedViews out, SfmViews(name, images, frame_of_image, image_names, calib_options, sfm,
                                                    warnings));
  timings->push_back({"calib", MsSince(calib_start)});
  return out;
}

// A lattice frame without a rig calibration (no layout, no lens poses): the lattice is found
// blind and the tiles are calibrated as an image set by structure from motion, with the lenses'
// intrinsics as metadata when the calibration has them for tiles of that size (else the focal
// length is self-calibrated: unobservable on a lattice of parallel lenses, which the report says).
StatusOr<CalibratedViews> BlindLatticeViews(const FrameSet& capture, const RigCalibration& rig,
                                            const CalibOptions& calib_options, const calib::SfmOptions& sfm,
                                            std::vector<std::string>* warnings, std::vector<StageTiming>* timings) {
  const Clock::time_point lattice_start = Clock::now();
  size_t chosen = capture.frames.size();
  for (size_t i = 0; i < capture.frames.size() && chosen == capture.frames.size(); ++i) {
    if (capture.frames[i].status == FrameStatus::kOk) chosen = i;
  }
  if (chosen == capture.frames.size()) return UnusableFrameError(capture, 0);
  const std::string name = FrameName(capture, chosen);
  PX_ASSIGN_OR_RETURN(cv::Mat sensor, ToBgr(capture.frames[chosen].image));
  StatusOr<LatticeDetection> found = DetectLattice(sensor, LatticeOptions());
  if (!found.ok()) {
    return FailedPreconditionError(name + ": no rig calibration, and the lattice cannot be found blind: " +
                                   found.status().message());
  }
  PX_ASSIGN_OR_RETURN(std::vector<cv::Mat> tiles, SplitLattice(sensor, found->layout));
  timings->push_back({"lattice", MsSince(lattice_start)});
  const std::string reason = "no factory rig calibration: lattice found blind (" + found->report.Summary() +
                             "); views calibrated by structure from motion";
  warnings->push_back(reason);
  Logger("calib")->warn("{}", reason);

  const Clock::time_point calib_start = Clock::now();
  std::vector<calib::SfmImage> images;
  std::vector<size_t> view_ids;
  std::vector<std::string> image_names;
  int with_intrinsics = 0;
  for (size_t i = 0; i < tiles.size(); ++i) {
    calib::SfmImage image;
    image.image = tiles[i];
    image.camera_id = 0;  // one lens design: self-calibrated intrinsics are shared
    if (rig.NumViews() == static_cast<int>(tiles.size())) {
      const CameraModel& lens = rig.lenses[i].camera;
      if (lens.width == tiles[i].cols && lens.height == tiles[i].rows) {
        image.intrinsics = lens;
        ++with_intrinsics;
      }
    }
    images.push_back(std::move(image));
    view_ids.push_back(i);
    image_names.push_back("view " + std::to_string(i));
  }
  if (with_intrinsics > 0) {
    warnings->push_back("calib: lens intrinsics of " + std::to_string(with_intrinsics) + " of " +
                        std::to_string(tiles.size()) + " tiles from the rig calibration's lenses (no layout)");
  }
  PX_ASSIGN_OR_RETURN(CalibratedViews out, SfmViews(name, images, view_ids, image_names, calib_options, sfm, warnings));
  out.calibration = "structure from motion (no rig calibration)";
  timings->push_back({"calib", MsSince(calib_start)});
  return out;
}

// Splits the lattice frame and makes the views, timing both stages. Image sets go through
// structure from motion instead.
StatusOr<CalibratedViews> CalibrateCapture(const FrameSet& capture, const RigCalibration& rig,
                                           const CalibOptions& calib, const calib::RigRefinementOptions& refinement,
                                           const calib::SfmOptions& sfm, std::vector<std::string>* warnings,
                                           std::vector<StageTiming>* timings) {
  if (capture.kind == FrameSetKind::kImageSet) {
    return ImageSetViews(capture, rig, calib, sfm, warnings, timings);
  }
  if (capture.frames.empty()) {
    return InvalidArgumentError("capture " + std::to_string(capture.capture_id) + " holds no frames");
  }
  if (rig.lattice.rows == 0) return BlindLatticeViews(capture, rig, calib, sfm, warnings, timings);
  PX_RETURN_IF_ERROR(rig.Validate().WithContext("rig calibration '" + rig.rig_name + "'"));

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
  // A salvaged frame lacks rows: its lattice cannot be checked as a whole.
  const LatticeLayout lattice = salvaged.empty() ? CheckedLattice(*sensor, rig, warnings) : rig.lattice;
  StatusOr<std::vector<cv::Mat>> tiles = SplitLattice(*sensor, lattice);
  if (!tiles.ok()) return tiles.status().WithContext(FrameName(capture, chosen));
  timings->push_back({"lattice", MsSince(lattice_start)});

  const Clock::time_point calib_start = Clock::now();
  CalibratedViews out;
  out.depth_min_m = rig.nominal_depth_min_m;
  out.depth_max_m = rig.nominal_depth_max_m;
  const RigCalibration shot_rig = RefinedRig(*tiles, rig, refinement, warnings, &out);
  PX_ASSIGN_OR_RETURN(std::vector<View> views, MakeViews(*tiles, shot_rig, calib));
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
  out.views = std::move(usable);
  return out;
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
  report->frame_coverage.clear();
  report->frame_coverage.reserve(num_frames);
  PX_RETURN_IF_ERROR(report_progress("render", 0));
  for (int i = 0; i < num_frames; ++i) {
    const double t = path.FrameTime(i);
    cv::Mat bgr;
    switch (path.kind) {
      case PathKind::kNovelView: {
        StatusOr<FrameRender> frame = renderer->Render(path.FrameAt(t));
        if (!frame.ok()) return frame.status().WithContext("render frame " + std::to_string(i));
        hole_sum += frame->holes.hole_ratio;
        report->frame_coverage.push_back(frame->holes);
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
  log->info("render ({}): {} frames of {}x{} ({}), {:.1f} ms each, {:.2f}% holes on average; sink {:.0f} ms",
            renderer != nullptr ? std::string(renderer->BackendName()) : std::string("2d"), num_frames,
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
  PX_RETURN_IF_ERROR(refinement.Validate().WithContext("pipeline.refinement"));
  PX_RETURN_IF_ERROR(sfm.Validate().WithContext("pipeline.sfm"));
  PX_RETURN_IF_ERROR(depth.Validate());
  PX_RETURN_IF_ERROR(direct.Validate());
  PX_RETURN_IF_ERROR(render.Validate());
  PX_RETURN_IF_ERROR(render_backend.Validate());
  if (num_threads < 0 || num_threads > 256) {
    return InvalidArgumentError("pipeline.num_threads: " + std::to_string(num_threads) + " is outside [0, 256]");
  }
  return OkStatus();
}

StatusOr<std::vector<View>> MakeViewsFromCapture(const FrameSet& capture, const RigCalibration& rig,
                                                 std::vector<std::string>* warnings, const CalibOptions& calib,
                                                 const calib::RigRefinementOptions& refinement,
                                                 const calib::SfmOptions& sfm) {
  std::vector<std::string> ignored;
  std::vector<StageTiming> timings;
  PX_RETURN_IF_ERROR(calib.Validate());
  PX_RETURN_IF_ERROR(refinement.Validate().WithContext("refinement"));
  PX_RETURN_IF_ERROR(sfm.Validate().WithContext("sfm"));
  PX_ASSIGN_OR_RETURN(CalibratedViews out, CalibrateCapture(capture, rig, calib, refinement, sfm,
                                                            warnings != nullptr ? warnings : &ignored, &timings));
  return std::move(out.views);
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
  StatusOr<CalibratedViews> made = CalibrateCapture(capture, rig, options.calib, options.refinement, options.sfm,
                                                    &report.warnings, &report.timings);
  if (!made.ok() && capture.kind == FrameSetKind::kImageSet &&
      (made.status().code() == StatusCode::kUnimplemented || made.status().code() == StatusCode::kFailedPrecondition)) {
    // Never fail the button: images that cannot be calibrated still morph (paper 4.5).
    return RunUncalibrated(capture, made.status(), options, sink, report_progress, std::move(report));
  }
  if (!made.ok()) return made.status();
  CalibratedViews calibrated = std::move(made).value();
  std::vector<View> views = std::move(calibrated.views);
  report.num_views = static_cast<int>(views.size());
  report.calibration = calibrated.calibration;
  report.calibration_summary = calibrated.summary;
  log->info("lattice: {} views of {}x{} in {:.0f} ms, calib in {:.0f} ms", views.size(), views.front().camera.width,
            views.front().camera.height, report.timings[0].ms, report.timings[1].ms);
  PX_RETURN_IF_ERROR(report_progress("calib", 1));

  // Stage 3: depth.
  Clock::time_point start = Clock::now();
  DepthOptions depth_options = options.depth.WithDefaultDepthRange(calibrated.depth_min_m, calibrated.depth_max_m);
  if (depth_options.num_threads == 0) depth_options.num_threads = options.num_threads;
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
  DirectionContext direction;
  {
    const double fraction = depth->report.confident_fraction;
    log->info("depth: {} layered views, {:.0f} to {:.2f} m, {:.0f}% confident, in {:.0f} ms", depth->maps.size(),
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
  // Views that match none of the others (a lens that saw another scene, a black or saturated
  // frame) would paint wrong colour at wrong depth: drop them while two views remain.
  std::vector<DepthMap> depth_maps = std::move(depth->maps);
  std::vector<LayeredDepthView> layers = std::move(depth->layered);
  if (!depth->report.disagreeing_views.empty() &&
      views.size() - depth->report.disagreeing_views.size() >= 2) {
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

  // Stage 4: the camera path, its viewpoints checked against what the renderer can cover.
  PX_RETURN_IF_ERROR(report_progress("direct", 0));
  start = Clock::now();
  PX_ASSIGN_OR_RETURN(std::unique_ptr<render::gl::BackendSceneRenderer> renderer,
                      render::gl::BackendSceneRenderer::Create(views, layers, options.render, options.render_backend));
  report.render_backend = std::string(renderer->BackendName());
  report.render_backend_reason = renderer->reason();
  for (const std::string& warning : renderer->warnings()) report.warnings.push_back("render: " + warning);
  direction.coverage = [&renderer](const CameraModel& camera, const Rigid3& cam_from_world) {
    return renderer->Coverage(camera, cam_from_world);
  };
  direction.face_detector = options.face_detector.get();
  direction.shot = options.shot.get();
  StatusOr<CameraPath> path = PlanCameraPath(views, depth_maps, options.direct, direction, &report.direction);
  if (!path.ok()) return path.status().WithContext("direct");
  report.path = *path;
  report.timings.push_back({"direct", MsSince(start)});
  LogDirection(report, &report.warnings);
  PX_RETURN_IF_ERROR(report_progress("direct", 1));

  // Stage 5: render every frame and hand it on.
  PX_RETURN_IF_ERROR(RenderFrames(views, renderer.get(), sink, report_progress, &report));
  if (renderer->cpu_fallback_frames() > 0) {
    report.warnings.push_back("render: " + std::to_string(renderer->cpu_fallback_frames()) + " frame(s) drawn on the cpu, " +
                              report.render_backend + " failed on them: " + renderer->cpu_fallback_reason());
  }
  return report;
}

}  // namespace px
