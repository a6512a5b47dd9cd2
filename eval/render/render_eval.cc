#include "eval/render/render_eval.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "eval/datasets/hci_light_field.h"
#include "eval/datasets/llff.h"
#include "eval/render/crack_measure.h"
#include "eval/render/image_metrics.h"
#include "eval/render/render_eval_steps.h"
#include "pipeline/calib/undistort_cache.h"
#include "pipeline/depth/depth_stage.h"
#include "pipeline/depth/plane_sweep.h"
#include "pipeline/render/cpu_scene_renderer.h"
#include "pipeline/render/layered_from_depth.h"
#include "sim/synthetic/ray_caster.h"
#include "sim/synthetic/scene_json.h"
#include "sim/synthetic/sim_sensor.h"

namespace px::eval {

void Progress(const RenderEvalOptions& options, const std::string& line) {
  if (options.progress) options.progress(line);
}

namespace {

using Clock = std::chrono::steady_clock;

StatusOr<std::vector<LayeredDepthView>> LayersFromDepthMaps(const std::vector<View>& views,
                                                            const std::vector<DepthMap>& depths,
                                                            const RenderEvalOptions& options) {
  std::vector<LayeredDepthView> layers;
  layers.reserve(views.size());
  for (size_t i = 0; i < views.size(); ++i) {
    StatusOr<LayeredDepthView> layered = LayeredDepthFromDepthMap(views[i], depths[i], options.layered);
    if (!layered.ok())
      return layered.status().WithContext("layered depth of view " + std::to_string(views[i].id.value));
    layers.push_back(std::move(layered).value());
  }
  return layers;
}

}  // namespace

StatusOr<std::unique_ptr<CpuSceneRenderer>> MakeRenderer(const std::vector<View>& views,
                                                         EvalDepth source,
                                                         double min_depth_m,
                                                         double max_depth_m,
                                                         const std::vector<DepthMap>* exact_depths,
                                                         const RenderEvalOptions& options) {
  std::vector<LayeredDepthView> layers;
  switch (source) {
    case EvalDepth::kDepthStage: {
      const DepthOptions depth_options = options.depth_stage.WithDefaultDepthRange(min_depth_m, max_depth_m);
      PX_ASSIGN_OR_RETURN(DepthStageResult depth, ComputeLayeredDepth(views, depth_options));
      layers = std::move(depth.layered);
      break;
    }
    case EvalDepth::kPlaneSweep: {
      PlaneSweepOptions sweep_options;
      sweep_options.min_depth_m = min_depth_m;
      sweep_options.max_depth_m = max_depth_m;
      PX_ASSIGN_OR_RETURN(std::vector<DepthMap> depths, ComputePlaneSweepDepth(views, sweep_options));
      PX_ASSIGN_OR_RETURN(layers, LayersFromDepthMaps(views, depths, options));
      break;
    }
    case EvalDepth::kTruth:
      if (exact_depths == nullptr || exact_depths->size() != views.size()) {
        return InvalidArgumentError("eval render: exact depth requested for a dataset without it");
      }
      PX_ASSIGN_OR_RETURN(layers, LayersFromDepthMaps(views, *exact_depths, options));
      break;
  }
  return CpuSceneRenderer::Create(views, layers, options.render);
}

std::vector<EvalDepth> DepthSources(const RenderEvalOptions& options, bool has_exact_depth) {
  std::vector<EvalDepth> sources;
  for (EvalDepth depth : options.depths) {
    if (depth != EvalDepth::kTruth || has_exact_depth) sources.push_back(depth);
  }
  return sources;
}

std::string DumpName(const std::string& dataset, const std::string& viewpoint, EvalDepth depth) {
  std::string name = dataset + " " + viewpoint + " " + std::string(EvalDepthName(depth));
  for (char& ch : name) {
    if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
  }
  return name;
}

StatusOr<RenderEvalCase> RenderCase(CpuSceneRenderer& renderer,
                                    const CameraModel& camera,
                                    const Rigid3& pose,
                                    const cv::Mat& truth,
                                    const cv::Mat& truth_depth_m,
                                    int num_sources,
                                    const RenderEvalOptions& options,
                                    const CaseLabel& label) {
  PX_ASSIGN_OR_RETURN(RenderEvalCase result,
                      RenderAndScore(renderer,
                                     camera,
                                     pose,
                                     truth,
                                     truth_depth_m,
                                     num_sources,
                                     options,
                                     DumpName(label.dataset, label.viewpoint, label.depth)));
  result.dataset = label.dataset;
  result.viewpoint = label.viewpoint;
  result.depth = label.depth;
  return result;
}

StatusOr<RenderEvalCase> RenderAndScore(CpuSceneRenderer& renderer,
                                        const CameraModel& camera,
                                        const Rigid3& pose,
                                        const cv::Mat& truth,
                                        const cv::Mat& truth_depth_m,
                                        int num_sources,
                                        const RenderEvalOptions& options,
                                        const std::string& dump_name,
                                        cv::Mat* render) {
  VirtualCamera virtual_camera;
  virtual_camera.camera = camera;
  virtual_camera.cam_from_world = pose;
  PX_RETURN_IF_ERROR(renderer.Render(virtual_camera).status());
  const Clock::time_point start = Clock::now();
  PX_ASSIGN_OR_RETURN(FrameRender frame, renderer.Render(virtual_camera));
  RenderEvalCase result;
  result.render_ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
  result.width = camera.width;
  result.height = camera.height;
  result.num_sources = num_sources;
  result.psnr_db = Psnr(frame.bgr, truth);
  result.ssim = Ssim(frame.bgr, truth);
  const cv::Mat edges = DepthEdgeBand(truth_depth_m.empty() ? frame.depth_m : truth_depth_m);
  const cv::Mat covered = frame.coverage != 0;
  result.psnr_covered_edges_db = Psnr(frame.bgr, truth, covered & edges);
  result.psnr_covered_flat_db = Psnr(frame.bgr, truth, covered & ~edges);
  result.psnr_holes_db = Psnr(frame.bgr, truth, ~covered);
  result.hole_ratio = frame.holes.hole_ratio;
  result.hole_score = frame.holes.hole_score;
  result.double_image_fraction = DoubleImageFraction(frame.double_image);
  cv::Mat cracks;
  if (!truth_depth_m.empty())
    result.crack_fraction = MeasureCracks(frame.depth_m, truth_depth_m, {}, &cracks).crack_fraction;
  if (!options.dump_dir.empty()) {
    std::error_code error;
    std::filesystem::create_directories(options.dump_dir, error);
    const std::string stem = (options.dump_dir / dump_name).string();
    cv::Mat diff;
    cv::absdiff(frame.bgr, truth, diff);
    diff.convertTo(diff, CV_8UC3, 4.0);
    if (!cv::imwrite(stem + "_render.png", frame.bgr) || !cv::imwrite(stem + "_truth.png", truth) ||
        !cv::imwrite(stem + "_error_x4.png", diff) || !cv::imwrite(stem + "_coverage.png", frame.coverage) ||
        (!cracks.empty() && !cv::imwrite(stem + "_cracks.png", cracks))) {
      return InternalError("eval render: cannot write " + stem + "_*.png");
    }
  }
  if (render != nullptr) *render = frame.bgr;
  return result;
}

StatusOr<std::unique_ptr<CpuSceneRenderer>> MakeSimLatticeRenderer(const SimLattice& lattice,
                                                                   EvalDepth source,
                                                                   const std::string& dataset,
                                                                   const RenderEvalOptions& options) {
  Progress(options,
           dataset + ": " + std::string(EvalDepthName(source)) + " depth for " + std::to_string(lattice.views.size()) +
               " views");
  return MakeRenderer(
      lattice.views, source, lattice.spec.depth_min_m, lattice.spec.depth_max_m, &lattice.depths, options);
}

Rigid3 PoseAt(const Eigen::Vector3d& centre_in_world, const Eigen::Quaterniond& cam_from_world_rotation) {
  return Rigid3(cam_from_world_rotation, -(cam_from_world_rotation * centre_in_world));
}

StatusOr<SimLattice> RenderSimLattice(const std::filesystem::path& scene_file,
                                      const SimCameraSpec& lattice,
                                      const RenderEvalOptions& options) {
  SimLattice out;
  PX_ASSIGN_OR_RETURN(out.scene, sim::LoadScene(scene_file));
  SimCameraSpec& spec = out.spec;
  spec = lattice;
  spec.tile_width = std::max(16, static_cast<int>(std::lround(spec.tile_width * options.sim_scale)));
  spec.tile_height = std::max(16, static_cast<int>(std::lround(spec.tile_height * options.sim_scale)));
  spec.focal_px *= options.sim_scale;
  spec.distortion = {0, 0, 0, 0, 0};
  out.dataset = "sim " + scene_file.stem().string() + " " + std::to_string(spec.cols) + "x" + std::to_string(spec.rows);
  Progress(options, out.dataset + ": ray casting " + std::to_string(spec.rows * spec.cols) + " views");
  PX_ASSIGN_OR_RETURN(std::vector<sim::ViewTruth> truths, sim::RenderLatticeViews(out.scene, spec));
  for (const sim::ViewTruth& truth : truths) {
    View view;
    view.id = truth.id;
    view.camera = truth.camera;
    view.cam_from_world = truth.cam_from_rig;
    view.image = truth.bgr;
    out.views.push_back(view);
    DepthMap depth;
    depth.id = truth.id;
    depth.depth_m = truth.depth_m;
    depth.confidence = cv::Mat(truth.depth_m.size(), CV_32F, cv::Scalar(1));
    out.depths.push_back(depth);
  }
  return out;
}

std::string_view EvalDepthName(EvalDepth depth) {
  switch (depth) {
    case EvalDepth::kDepthStage:
      return "depth stage";
    case EvalDepth::kTruth:
      return "exact";
    case EvalDepth::kPlaneSweep:
      return "plane sweep";
  }
  return "?";
}

StatusOr<EvalDepth> ParseEvalDepth(std::string_view name) {
  if (name == "depth stage" || name == "stage") return EvalDepth::kDepthStage;
  if (name == "exact" || name == "truth") return EvalDepth::kTruth;
  if (name == "plane sweep" || name == "sweep") return EvalDepth::kPlaneSweep;
  return InvalidArgumentError("eval render: depth source '" + std::string(name) +
                              "' is not one of stage, truth, sweep");
}

Status RenderEvalOptions::Validate() const {
  PX_RETURN_IF_ERROR(render.Validate());
  if (depths.empty()) return InvalidArgumentError("eval render: no depth source to evaluate (depths is empty)");
  if (!(sim_scale > 0 && sim_scale <= 1)) {
    std::ostringstream error;
    error << "eval render: sim_scale " << sim_scale << " is outside (0, 1]";
    return InvalidArgumentError(error.str());
  }
  if (llff_hold_out_every < 2 || llff_hold_out_every > 100) {
    return InvalidArgumentError("eval render: llff_hold_out_every " + std::to_string(llff_hold_out_every) +
                                " is outside [2, 100]");
  }
  return OkStatus();
}

StatusOr<std::vector<RenderEvalCase>> EvaluateSimulatedScene(const std::filesystem::path& scene_file,
                                                             const SimCameraSpec& lattice,
                                                             const RenderEvalOptions& options) {
  PX_RETURN_IF_ERROR(options.Validate());
  PX_ASSIGN_OR_RETURN(SimLattice sim_lattice, RenderSimLattice(scene_file, lattice, options));
  const sim::Scene& scene = sim_lattice.scene;
  const SimCameraSpec& spec = sim_lattice.spec;
  const std::string& dataset = sim_lattice.dataset;
  const std::vector<View>& views = sim_lattice.views;

  // Viewpoints no lens had: between lenses on the lattice plane, off the plane in front of and
  // behind it, and turned. The rig frame is centred on the lattice, lenses looking down +z.
  const double b = spec.baseline_m;
  const Eigen::Quaterniond straight = Eigen::Quaterniond::Identity();
  const Eigen::Quaterniond turned(Eigen::AngleAxisd(2.0 * M_PI / 180, Eigen::Vector3d::UnitY()) *
                                  Eigen::AngleAxisd(1.0 * M_PI / 180, Eigen::Vector3d::UnitX()));
  struct Viewpoint {
    std::string name;
    Eigen::Vector3d centre;
    Eigen::Quaterniond rotation;
  };
  const std::vector<Viewpoint> viewpoints = {
      {"between lenses", Eigen::Vector3d(0.5 * b, 0.5 * b, 0), straight},
      {"5 cm in front of the lattice", Eigen::Vector3d(0.25 * b, -0.3 * b, 0.05), straight},
      {"5 cm behind the lattice", Eigen::Vector3d(-0.3 * b, 0.2 * b, -0.05), straight},
      {"between lenses, turned 2 deg", Eigen::Vector3d(0.4 * b, -0.4 * b, 0.01), turned},
  };
  sim::RenderOptions truth_options;
  truth_options.supersampling = spec.supersampling;
  const CameraModel& camera = views.front().camera;
  std::vector<cv::Mat> truth_images, truth_depths;
  for (const Viewpoint& viewpoint : viewpoints) {
    PX_ASSIGN_OR_RETURN(sim::RenderedView truth,
                        sim::RenderView(scene, camera, PoseAt(viewpoint.centre, viewpoint.rotation), truth_options));
    truth_images.push_back(truth.bgr);
    truth_depths.push_back(truth.depth_m);
  }
  std::vector<RenderEvalCase> cases;
  for (EvalDepth source : DepthSources(options, true)) {
    PX_ASSIGN_OR_RETURN(std::unique_ptr<CpuSceneRenderer> renderer,
                        MakeSimLatticeRenderer(sim_lattice, source, dataset, options));
    for (size_t i = 0; i < viewpoints.size(); ++i) {
      Progress(options, dataset + ": " + viewpoints[i].name);
      const Rigid3 pose = PoseAt(viewpoints[i].centre, viewpoints[i].rotation);
      PX_ASSIGN_OR_RETURN(RenderEvalCase result,
                          RenderCase(*renderer,
                                     camera,
                                     pose,
                                     truth_images[i],
                                     truth_depths[i],
                                     static_cast<int>(views.size()),
                                     options,
                                     {dataset, viewpoints[i].name, source}));
      cases.push_back(result);
    }
  }
  return cases;
}

StatusOr<std::vector<RenderEvalCase>> EvaluateHciCentreView(const std::filesystem::path& dir,
                                                            const RenderEvalOptions& options) {
  PX_RETURN_IF_ERROR(options.Validate());
  PX_ASSIGN_OR_RETURN(HciLightField field, LoadHciLightField(dir));
  const std::string dataset = "hci " + field.scene;
  const View& centre = field.views[field.CentreIndex()];
  // The depth stage's range from the scene's disparity range, with a margin.
  const double lo = std::max(field.disp_min, -field.offset_px + 0.1), hi = field.disp_max;
  // Depth edges from the ground truth where the set has it at the image's size.
  const cv::Mat truth_depth = field.gt_disparity.size() == centre.image.size() ? field.GtDepth() : cv::Mat();
  const double min_depth_m = 0.9 * field.DepthFromDisparity(hi);
  const double max_depth_m = 1.1 * field.DepthFromDisparity(lo);
  std::vector<std::pair<std::string, std::vector<View>>> sets;
  std::vector<View> ring = field.CentreGrid(1);
  ring.erase(ring.begin() + static_cast<long>(ring.size() / 2));
  sets.emplace_back("centre from its 3x3 ring (8 views)", ring);
  if (options.hci_full_grid) {
    std::vector<View> all = field.views;
    all.erase(all.begin() + field.CentreIndex());
    sets.emplace_back("centre from the 9x9 (80 views)", all);
  }
  std::vector<RenderEvalCase> cases;
  for (const auto& [name, sources] : sets) {
    for (EvalDepth source : DepthSources(options, false)) {
      Progress(options,
               dataset + ": " + std::string(EvalDepthName(source)) + " depth for " + std::to_string(sources.size()) +
                   " views");
      PX_ASSIGN_OR_RETURN(std::unique_ptr<CpuSceneRenderer> renderer,
                          MakeRenderer(sources, source, min_depth_m, max_depth_m, nullptr, options));
      Progress(options, dataset + ": " + name);
      PX_ASSIGN_OR_RETURN(RenderEvalCase result,
                          RenderCase(*renderer,
                                     centre.camera,
                                     centre.cam_from_world,
                                     centre.image,
                                     truth_depth,
                                     static_cast<int>(sources.size()),
                                     options,
                                     {dataset, name, source}));
      cases.push_back(result);
    }
  }
  return cases;
}

StatusOr<std::vector<RenderEvalCase>> EvaluateLlffHeldOut(const std::filesystem::path& dir,
                                                          const RenderEvalOptions& options) {
  PX_RETURN_IF_ERROR(options.Validate());
  PX_ASSIGN_OR_RETURN(LlffScene scene, LoadLlffScene(dir));
  const std::string dataset = "llff " + dir.filename().string();
  // The renderer and the depth stage take undistorted pinholes: remove COLMAP's k1.
  UndistortCache undistort;
  double near = 1e30, far = 0;
  for (size_t i = 0; i < scene.views.size(); ++i) {
    View& view = scene.views[i];
    if (view.camera.HasDistortion()) {
      const UndistortCache::Maps& maps = undistort.Get(view.camera);
      cv::Mat undistorted;
      cv::remap(view.image, undistorted, maps.map_x, maps.map_y, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
      view.image = undistorted;
      view.camera = view.camera.WithoutDistortion();
    }
    near = std::min(near, scene.near_depth[i]);
    far = std::max(far, scene.far_depth[i]);
  }
  std::vector<View> sources, held_out;
  for (size_t i = 0; i < scene.views.size(); ++i) {
    (static_cast<int>(i) % options.llff_hold_out_every == 0 ? held_out : sources).push_back(scene.views[i]);
  }
  if (sources.size() < 2 || held_out.empty()) {
    return InvalidArgumentError(dataset + ": " + std::to_string(scene.views.size()) +
                                " views are too few to hold out every " + std::to_string(options.llff_hold_out_every));
  }
  std::vector<RenderEvalCase> cases;
  for (EvalDepth source : DepthSources(options, false)) {
    Progress(options,
             dataset + ": " + std::string(EvalDepthName(source)) + " depth for " + std::to_string(sources.size()) +
                 " views");
    PX_ASSIGN_OR_RETURN(std::unique_ptr<CpuSceneRenderer> renderer,
                        MakeRenderer(sources, source, 0.8 * near, 1.2 * far, nullptr, options));
    for (const View& view : held_out) {
      const std::string name = "view " + std::to_string(view.id.value) + " held out";
      Progress(options, dataset + ": " + name);
      PX_ASSIGN_OR_RETURN(RenderEvalCase result,
                          RenderCase(*renderer,
                                     view.camera,
                                     view.cam_from_world,
                                     view.image,
                                     cv::Mat(),
                                     static_cast<int>(sources.size()),
                                     options,
                                     {dataset, name, source}));
      cases.push_back(result);
    }
  }
  return cases;
}

}  // namespace px::eval
