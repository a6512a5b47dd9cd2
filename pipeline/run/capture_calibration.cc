#include "pipeline/run/capture_calibration.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "pipeline/calib/incremental_sfm.h"
#include "pipeline/calib/make_views.h"
#include "pipeline/calib/rig_refinement.h"
#include "pipeline/calib/undistort_cache.h"
#include "pipeline/core/log.h"
#include "pipeline/core/pixel_format.h"
#include "pipeline/core/stage_clock.h"
#include "pipeline/lattice/lattice_detector.h"
#include "pipeline/lattice/split_lattice.h"
#include "pipeline/run/frame_salvage.h"

namespace px {

namespace {

// A tile whose grey levels vary less than this (standard deviation, 8-bit levels) shows no
// scene: a covered, dead or unlit lens. Sensor noise alone exceeds it on any real image.
constexpr double kBlankTileStddev = 1.0;

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
  std::snprintf(text,
                sizeof(text),
                "lattice moved: tiles found up to %.1f px from the rig calibration's layout (confidence %.2f); "
                "cut at the found positions with the calibrated intrinsics",
                found->report.max_prior_shift_px,
                found->report.confidence);
  warnings->push_back(text);
  return moved;
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
size_t SalvageFrame(const FrameSet& capture,
                    const LatticeLayout& lattice,
                    cv::Mat* bgr,
                    int* complete_rows,
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

// Refines the factory calibration from the tiles when enabled; the factory's otherwise or
// when refinement is not trustworthy (the reason in `warnings`).
RigCalibration RefinedRig(const std::vector<cv::Mat>& tiles,
                          const RigCalibration& rig,
                          const calib::RigRefinementOptions& refinement,
                          std::vector<std::string>* warnings,
                          CalibratedViews* out) {
  out->calibration = "factory";
  out->metric_scale = true;  // the rig's baselines are measured
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
  char text[320];
  std::snprintf(text,
                sizeof(text),
                "%d lens pairs, %d matches, %d inliers, %d tracks, reprojection RMS %.2f -> %.2f px, max change "
                "%.3f deg, %.2f mm, focal %.2f %%, %.0f ms (features %.0f, matching %.0f, adjustment %.0f)",
                report.num_pairs,
                report.num_matches,
                report.num_inliers,
                report.num_tracks,
                report.rms_before_px,
                report.rms_after_px,
                report.max_rotation_change_deg,
                1000 * report.max_centre_change_m,
                100 * report.max_focal_change_relative,
                report.total_ms,
                report.features_ms,
                report.matching_ms,
                report.adjustment_ms);
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
StatusOr<CalibratedViews> SfmViews(const std::string& name,
                                   const std::vector<calib::SfmImage>& images,
                                   const std::vector<size_t>& view_ids,
                                   const std::vector<std::string>& image_names,
                                   const CalibOptions& calib_options,
                                   const calib::SfmOptions& sfm,
                                   std::vector<std::string>* warnings) {
  PX_ASSIGN_OR_RETURN(calib::SfmResult sfm_result, calib::RunIncrementalSfm(images, sfm));
  const calib::SfmReport& report = sfm_result.report;
  if (!report.success) {
    return FailedPreconditionError(name + ": structure from motion failed: " + report.failure);
  }
  for (const std::string& warning : report.warnings) warnings->push_back("calib: " + warning);
  CalibratedViews out;
  out.calibration = "structure from motion";
  char text[320];
  std::snprintf(text,
                sizeof(text),
                "%d of %d images registered, %d points, reprojection RMS %.2f px, focal %s%s, %.0f ms (features %.0f, "
                "matching %.0f, reconstruction %.0f)",
                report.num_registered,
                report.num_images,
                report.num_points,
                report.rms_px,
                report.focal_source.c_str(),
                report.focal_observable ? "" : " (unobservable)",
                report.total_ms,
                report.features_ms,
                report.matching_ms,
                report.reconstruction_ms);
  out.summary = text;
  std::vector<double> nears, fars;
  UndistortCache cache;
  for (size_t i = 0; i < images.size(); ++i) {
    const calib::SfmView& sfm_view = sfm_result.views[i];
    if (!sfm_view.registered) {
      warnings->push_back(image_names[i] + " not registered: " + sfm_view.note + "; dropped");
      continue;
    }
    PX_ASSIGN_OR_RETURN(View view,
                        MakeView(ViewId{static_cast<int>(view_ids[i])},
                                 images[i].image,
                                 sfm_view.camera,
                                 sfm_view.cam_from_world,
                                 calib_options,
                                 &cache));
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
StatusOr<CalibratedViews> ImageSetViews(const FrameSet& capture,
                                        const RigCalibration& rig,
                                        const CalibOptions& calib_options,
                                        const calib::SfmOptions& sfm,
                                        std::vector<std::string>* warnings,
                                        std::vector<StageTiming>* timings) {
  const std::string name = "capture " + std::to_string(capture.capture_id);
  if (capture.frames.size() < 2) {
    return FailedPreconditionError(name + ": an image set needs at least 2 images, got " +
                                   std::to_string(capture.frames.size()));
  }
  const StageClock::time_point start = StageClock::now();
  std::vector<calib::SfmImage> images;
  std::vector<size_t> frame_of_image;
  int with_exif_focal = 0;
  for (size_t i = 0; i < capture.frames.size(); ++i) {
    const Frame& frame = capture.frames[i];
    StatusOr<cv::Mat> bgr =
        frame.status == FrameStatus::kOk ? ToBgr(frame.image) : StatusOr<cv::Mat>(UnusableFrameError(capture, i));
    if (!bgr.ok()) {
      warnings->push_back(FrameName(capture, i) + " skipped: " + bgr.status().ToString());
      continue;
    }
    calib::SfmImage image;
    image.image = *bgr;
    // A rig with one lens per image (a replayed, calibrated set) gives the intrinsics; else the
    // image's own focal length (EXIF) when it has one, with the principal point at the centre.
    if (rig.NumViews() == static_cast<int>(capture.frames.size())) {
      const CameraModel& lens = rig.lenses[i].camera;
      if (lens.width == bgr->cols && lens.height == bgr->rows) image.intrinsics = lens;
    }
    if (image.intrinsics.fx == 0 && frame.focal_length_px > 0) {
      image.intrinsics = CameraModel::Pinhole(bgr->cols, bgr->rows, frame.focal_length_px);
      ++with_exif_focal;
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
  const StageClock::time_point calib_start = StageClock::now();
  PX_ASSIGN_OR_RETURN(CalibratedViews out,
                      SfmViews(name, images, frame_of_image, image_names, calib_options, sfm, warnings));
  if (with_exif_focal > 0) {
    out.summary += "; focal length of " + std::to_string(with_exif_focal) + " of " + std::to_string(images.size()) +
                   " images from their metadata (" + capture.frames[frame_of_image[0]].focal_length_source + ")";
  }
  timings->push_back({"calib", MsSince(calib_start)});
  return out;
}

// A lattice frame without a rig calibration (no layout, no lens poses): the lattice is found
// blind and the tiles are calibrated as an image set by structure from motion, with the lenses'
// intrinsics as metadata when the calibration has them for tiles of that size (else the focal
// length is self-calibrated: unobservable on a lattice of parallel lenses, which the report says).
StatusOr<CalibratedViews> BlindLatticeViews(const FrameSet& capture,
                                            const RigCalibration& rig,
                                            const CalibOptions& calib_options,
                                            const calib::SfmOptions& sfm,
                                            const LatticeOptions& lattice,
                                            std::vector<std::string>* warnings,
                                            std::vector<StageTiming>* timings) {
  const StageClock::time_point lattice_start = StageClock::now();
  size_t chosen = capture.frames.size();
  for (size_t i = 0; i < capture.frames.size() && chosen == capture.frames.size(); ++i) {
    if (capture.frames[i].status == FrameStatus::kOk) chosen = i;
  }
  if (chosen == capture.frames.size()) return UnusableFrameError(capture, 0);
  const std::string name = FrameName(capture, chosen);
  PX_ASSIGN_OR_RETURN(cv::Mat sensor, ToBgr(capture.frames[chosen].image));
  StatusOr<LatticeDetection> found = DetectLattice(sensor, lattice);
  if (!found.ok()) {
    return FailedPreconditionError(
        name + ": no rig calibration, and the lattice cannot be found blind: " + found.status().message());
  }
  PX_ASSIGN_OR_RETURN(std::vector<cv::Mat> tiles, SplitLattice(sensor, found->layout));
  timings->push_back({"lattice", MsSince(lattice_start)});
  const std::string reason = "no factory rig calibration: lattice found blind (" + found->report.Summary() +
                             "); views calibrated by structure from motion";
  warnings->push_back(reason);
  Logger("calib")->warn("{}", reason);

  const StageClock::time_point calib_start = StageClock::now();
  std::vector<calib::SfmImage> images;
  std::vector<size_t> view_ids;
  std::vector<std::string> image_names;
  int with_intrinsics = 0, with_metadata_focal = 0;
  // A photo's focal length (EXIF) is the lenses' too: they share the frame's pixels.
  const double frame_focal_px = capture.frames[chosen].focal_length_px;
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
    if (image.intrinsics.fx == 0 && frame_focal_px > 0) {
      image.intrinsics = CameraModel::Pinhole(tiles[i].cols, tiles[i].rows, frame_focal_px);
      ++with_metadata_focal;
    }
    images.push_back(std::move(image));
    view_ids.push_back(i);
    image_names.push_back("view " + std::to_string(i));
  }
  if (with_intrinsics > 0) {
    warnings->push_back("calib: lens intrinsics of " + std::to_string(with_intrinsics) + " of " +
                        std::to_string(tiles.size()) + " tiles from the rig calibration's lenses (no layout)");
  }
  if (with_metadata_focal > 0) {
    warnings->push_back("calib: the lenses' focal length from the frame's metadata (" +
                        capture.frames[chosen].focal_length_source + ")");
  }
  PX_ASSIGN_OR_RETURN(CalibratedViews out, SfmViews(name, images, view_ids, image_names, calib_options, sfm, warnings));
  out.calibration = "structure from motion (no rig calibration)";
  timings->push_back({"calib", MsSince(calib_start)});
  return out;
}

}  // namespace

std::string FrameName(const FrameSet& capture, size_t index) {
  const Frame& frame = capture.frames[index];
  return "capture " + std::to_string(capture.capture_id) + " frame " + std::to_string(index) + " (sequence " +
         std::to_string(frame.sequence) + ")";
}

// Splits the lattice frame and makes the views, timing both stages. Image sets go through
// structure from motion instead.
StatusOr<CalibratedViews> CalibrateCapture(const FrameSet& capture,
                                           const RigCalibration& rig,
                                           const CalibOptions& calib,
                                           const calib::RigRefinementOptions& refinement,
                                           const calib::SfmOptions& sfm,
                                           std::vector<std::string>* warnings,
                                           std::vector<StageTiming>* timings,
                                           const LatticeOptions& blind_lattice) {
  if (capture.kind == FrameSetKind::kImageSet) {
    return ImageSetViews(capture, rig, calib, sfm, warnings, timings);
  }
  if (capture.frames.empty()) {
    return InvalidArgumentError("capture " + std::to_string(capture.capture_id) + " holds no frames");
  }
  if (rig.lattice.rows == 0) return BlindLatticeViews(capture, rig, calib, sfm, blind_lattice, warnings, timings);
  PX_RETURN_IF_ERROR(rig.Validate().WithContext("rig calibration '" + rig.rig_name + "'"));

  const StageClock::time_point lattice_start = StageClock::now();
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
    warnings->push_back(
        FrameName(capture, i) + " skipped: a lattice capture needs one frame, used frame " + std::to_string(chosen) +
        (capture.frames[i].status == FrameStatus::kOk
             ? ""
             : std::string(" (this one is ") + std::string(FrameStatusName(capture.frames[i].status)) + ")"));
  }
  StatusOr<cv::Mat> sensor = salvaged.empty() ? ToBgr(capture.frames[chosen].image) : StatusOr<cv::Mat>(salvaged);
  if (!sensor.ok()) return sensor.status().WithContext(FrameName(capture, chosen));
  // A salvaged frame lacks rows: its lattice cannot be checked as a whole.
  const LatticeLayout lattice = salvaged.empty() ? CheckedLattice(*sensor, rig, warnings) : rig.lattice;
  StatusOr<std::vector<cv::Mat>> tiles = SplitLattice(*sensor, lattice);
  if (!tiles.ok()) return tiles.status().WithContext(FrameName(capture, chosen));
  timings->push_back({"lattice", MsSince(lattice_start)});

  const StageClock::time_point calib_start = StageClock::now();
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
      std::snprintf(text,
                    sizeof(text),
                    "view %d is blank (grey mean %.1f, stddev %.2f): lens covered or dead",
                    view.id.value,
                    mean[0],
                    stddev[0]);
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

}  // namespace px
