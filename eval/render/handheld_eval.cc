#include "eval/render/handheld_eval.h"

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <opencv2/core.hpp>
#include <string>

#include "eval/calib/pose_alignment.h"
#include "eval/render/render_eval_steps.h"
#include "pipeline/core/pixel_format.h"
#include "pipeline/run/capture_calibration.h"
#include "sim/synthetic/handheld_photos.h"
#include "sim/synthetic/ray_caster.h"
#include "sim/synthetic/scene_json.h"

namespace px::eval {
namespace {

constexpr double kFocalPx = 560;     // at 640x480
constexpr double kNoiseSigma = 2.0;  // 8-bit levels, as eval/calib's simulated hand-held sets

// The shots (sim/synthetic/handheld_photos.h) and the viewpoints scored, each taken as a photo
// too: posed with the others, left out of the sources (LLFF's protocol).
using Place = sim::HandHeldPlace;
struct Viewpoint {
  const char* name;
  Place place;
};
const Viewpoint kViewpoints[] = {{"between shots", {{0.0, 0.002, 0.0}, {0, 0, 0}}},
                                 {"5 cm in front of the shots", {{-0.02, 0.0, 0.05}, {0, 0, 0}}},
                                 {"between shots, turned 2 deg", {{0.02, 0.0, 0.0}, {0, 2, 0}}}};

// A subject that moves between the shots: in shot i the face plane is turned by kFaceTurnDeg[i]
// about its vertical axis and moved kFaceShiftM[i] sideways (a sitter turning her head over the
// seconds a hand-held set takes).
constexpr double kFaceTurnDeg[] = {-9, -3, 3, 9};
constexpr double kFaceShiftM[] = {-0.015, -0.005, 0.005, 0.015};

// `scene` with its plane named "face" turned and shifted; NOT_FOUND when it has none.
StatusOr<sim::Scene> WithFaceMoved(const sim::Scene& scene, double turn_deg, double shift_m) {
  sim::Scene moved = scene;
  for (sim::Plane& plane : moved.planes) {
    if (plane.name != "face") continue;
    const Eigen::Matrix3d turn = Eigen::AngleAxisd(turn_deg * M_PI / 180, plane.down).toRotationMatrix();
    plane.normal = turn * plane.normal;
    plane.right = turn * plane.right;
    plane.centre_m += shift_m * plane.right;
    return moved;
  }
  return NotFoundError(scene.name + ": no plane named 'face' to move between the shots");
}

// The cases of one set of photos: with the focal length as EXIF gives it, or without (phones'
// photos passed through messaging apps lose their EXIF), self-calibrated.
// `scenes[i]` is the scene photo i saw (the shots, then the held-out viewpoints; one scene for all
// when the subject keeps still).
StatusOr<std::vector<RenderEvalCase>> EvaluateShots(const std::vector<const sim::Scene*>& scenes,
                                                    const std::string& dataset,
                                                    bool exif,
                                                    const RenderEvalOptions& options) {
  const auto scene_of = [&](size_t place) -> const sim::Scene& { return *scenes[std::min(place, scenes.size() - 1)]; };
  const double s = options.sim_scale;
  const CameraModel camera = CameraModel::Pinhole(
      static_cast<int>(std::lround(640 * s)), static_cast<int>(std::lround(480 * s)), kFocalPx * s);

  // The shots, as the camera delivers them (noise, the focal length as EXIF gives it).
  const std::vector<Place>& shots = sim::HandHeldPlaces();
  const size_t num_sources = shots.size();
  std::vector<Place> places = shots;
  for (const Viewpoint& viewpoint : kViewpoints) places.push_back(viewpoint.place);
  Progress(options, dataset + ": ray casting " + std::to_string(places.size()) + " photos");
  FrameSet capture;
  capture.kind = FrameSetKind::kImageSet;
  std::vector<Rigid3> true_poses;
  for (size_t i = 0; i < places.size(); ++i) {
    true_poses.push_back(sim::CamFromWorldAt(places[i]));
    PX_ASSIGN_OR_RETURN(sim::RenderedView shot, sim::RenderView(scene_of(i), camera, true_poses.back()));
    cv::Mat noise(shot.bgr.size(), CV_16SC3), noisy;
    cv::RNG rng(100 + i);
    rng.fill(noise, cv::RNG::NORMAL, 0, kNoiseSigma);
    shot.bgr.convertTo(noisy, CV_16SC3);
    noisy += noise;
    noisy.convertTo(shot.bgr, CV_8UC3);
    Frame frame;
    PX_ASSIGN_OR_RETURN(frame.image, FromBgr(shot.bgr, PixelFormat::kRgb888));
    frame.sequence = i;
    frame.focal_length_px = exif ? camera.fx : 0.0;
    if (exif) frame.focal_length_source = "simulated EXIF";
    capture.frames.push_back(std::move(frame));
  }

  // The product's calibration of them all; the scale of its frame from its alignment onto the
  // truth (for the exact depth).
  Progress(options, dataset + ": structure from motion");
  std::vector<std::string> warnings;
  std::vector<StageTiming> timings;
  PX_ASSIGN_OR_RETURN(CalibratedViews calibrated,
                      CalibrateCapture(capture,
                                       RigCalibration{},
                                       CalibOptions{},
                                       calib::RigRefinementOptions{},
                                       calib::SfmOptions{},
                                       &warnings,
                                       &timings));
  std::vector<Rigid3> estimated, reference;
  std::vector<double> estimated_focal, reference_focal;
  for (const View& view : calibrated.views) {
    estimated.push_back(view.cam_from_world);
    reference.push_back(true_poses[static_cast<size_t>(view.id.value)]);
    estimated_focal.push_back(view.camera.fx);
    reference_focal.push_back(camera.fx);
  }
  PX_ASSIGN_OR_RETURN(PoseErrors pose_errors, ComparePoses(estimated, reference, estimated_focal, reference_focal));
  const Similarity& align = pose_errors.alignment;
  char posed[200];
  std::snprintf(posed,
                sizeof(posed),
                "%s: %zu of %zu photos posed; after alignment, rotation within %.3f deg, "
                "centres within %.1f %% of the 8 cm baseline, focal within %.2f %%",
                dataset.c_str(),
                calibrated.views.size(),
                places.size(),
                PoseErrors::Max(pose_errors.rotation_deg),
                100 * PoseErrors::Max(pose_errors.centre_relative),
                100 * PoseErrors::Max(pose_errors.focal_relative));
  Progress(options, posed);

  // The sources, and the held-out photos' cameras as the reconstruction has them.
  std::vector<View> sources;
  std::map<size_t, const View*> held_out;
  for (const View& view : calibrated.views) {
    const size_t place = static_cast<size_t>(view.id.value);
    if (place < num_sources) {
      sources.push_back(view);
    } else {
      held_out[place - num_sources] = &view;
    }
  }
  if (sources.size() < 2) {
    return FailedPreconditionError(dataset + ": structure from motion posed " + std::to_string(sources.size()) +
                                   " of the " + std::to_string(num_sources) + " source shots");
  }
  // Exact depth in the reconstruction's units (depth scales by 1 / s).
  std::vector<DepthMap> exact;
  for (const View& view : sources) {
    PX_ASSIGN_OR_RETURN(
        sim::RenderedView truth,
        sim::RenderView(
            scene_of(static_cast<size_t>(view.id.value)), camera, true_poses[static_cast<size_t>(view.id.value)]));
    DepthMap map;
    map.id = view.id;
    map.depth_m = truth.depth_m / align.scale;
    map.confidence = cv::Mat(truth.depth_m.size(), CV_32F, cv::Scalar(1));
    exact.push_back(std::move(map));
  }

  std::vector<RenderEvalCase> cases;
  for (EvalDepth source : DepthSources(options, true)) {
    Progress(options, dataset + ": " + std::string(EvalDepthName(source)));
    PX_ASSIGN_OR_RETURN(std::unique_ptr<CpuSceneRenderer> renderer,
                        MakeRenderer(sources, source, calibrated.depth_min_m, calibrated.depth_max_m, &exact, options));
    for (size_t k = 0; k < std::size(kViewpoints); ++k) {
      const Viewpoint& viewpoint = kViewpoints[k];
      const auto posed_view = held_out.find(k);
      if (posed_view == held_out.end()) {
        Progress(options, dataset + ": " + viewpoint.name + ": its photo was not posed; no case");
        continue;
      }
      PX_ASSIGN_OR_RETURN(sim::RenderedView truth,
                          sim::RenderView(scene_of(num_sources + k), camera, sim::CamFromWorldAt(viewpoint.place)));
      const cv::Mat truth_depth = truth.depth_m / align.scale;
      PX_ASSIGN_OR_RETURN(RenderEvalCase result,
                          RenderCase(*renderer,
                                     posed_view->second->camera,
                                     posed_view->second->cam_from_world,
                                     truth.bgr,
                                     truth_depth,
                                     static_cast<int>(sources.size()),
                                     options,
                                     {dataset, viewpoint.name, source}));
      cases.push_back(result);
    }
  }
  return cases;
}

}  // namespace

StatusOr<std::vector<RenderEvalCase>> EvaluateSimulatedHandheld(const std::filesystem::path& scene_file,
                                                                const RenderEvalOptions& options) {
  PX_RETURN_IF_ERROR(options.Validate());
  PX_ASSIGN_OR_RETURN(sim::Scene scene, sim::LoadScene(scene_file));
  const std::string dataset = "sim " + scene_file.stem().string() + " hand-held";
  PX_ASSIGN_OR_RETURN(std::vector<RenderEvalCase> cases, EvaluateShots({&scene}, dataset, true, options));
  PX_ASSIGN_OR_RETURN(std::vector<RenderEvalCase> without,
                      EvaluateShots({&scene}, dataset + " no EXIF", false, options));
  cases.insert(cases.end(), without.begin(), without.end());
  return cases;
}

StatusOr<std::vector<RenderEvalCase>> EvaluateSimulatedHandheldMotion(const std::filesystem::path& scene_file,
                                                                      const RenderEvalOptions& options) {
  PX_RETURN_IF_ERROR(options.Validate());
  PX_ASSIGN_OR_RETURN(sim::Scene scene, sim::LoadScene(scene_file));
  std::vector<sim::Scene> shot_scenes;
  for (size_t i = 0; i < sim::HandHeldPlaces().size(); ++i) {
    PX_ASSIGN_OR_RETURN(sim::Scene moved, WithFaceMoved(scene, kFaceTurnDeg[i], kFaceShiftM[i]));
    shot_scenes.push_back(std::move(moved));
  }
  // The shots, then each held-out viewpoint with the face as the nearest shot saw it.
  std::vector<const sim::Scene*> scenes;
  for (const sim::Scene& shot : shot_scenes) scenes.push_back(&shot);
  for (const Viewpoint& viewpoint : kViewpoints) {
    size_t nearest = 0;
    for (size_t i = 1; i < sim::HandHeldPlaces().size(); ++i) {
      if ((sim::HandHeldPlaces()[i].centre_m - viewpoint.place.centre_m).norm() <
          (sim::HandHeldPlaces()[nearest].centre_m - viewpoint.place.centre_m).norm()) {
        nearest = i;
      }
    }
    scenes.push_back(&shot_scenes[nearest]);
  }
  RenderEvalOptions measured = options;
  measured.render.measure_double_images = true;
  return EvaluateShots(scenes, "sim " + scene_file.stem().string() + " hand-held, face turning", true, measured);
}

}  // namespace px::eval
