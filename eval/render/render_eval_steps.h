// The steps every case group of the render evaluation shares (render_eval.cc): the renderer over a
// depth source, one viewpoint rendered and scored against its truth, the simulated lattice with its
// exact depth. For the case groups in their own files (closeup_eval.h); not a public interface.
#pragma once

#include <Eigen/Geometry>
#include <filesystem>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "eval/render/render_eval.h"
#include "pipeline/core/view.h"
#include "pipeline/render/cpu_scene_renderer.h"
#include "sim/synthetic/scene.h"

namespace px::eval {

// Calls options.progress with `line` when it is set.
void Progress(const RenderEvalOptions& options, const std::string& line);

// The renderer over `views` with layered depth from `source`: the depth stage or the plane sweep
// over [min_depth_m, max_depth_m], or `exact_depths` (kTruth; must then hold one map per view).
StatusOr<std::unique_ptr<CpuSceneRenderer>> MakeRenderer(const std::vector<View>& views,
                                                         EvalDepth source,
                                                         double min_depth_m,
                                                         double max_depth_m,
                                                         const std::vector<DepthMap>* exact_depths,
                                                         const RenderEvalOptions& options);

// The depth sources of `options` that apply to a dataset (kTruth only where exact depth exists).
std::vector<EvalDepth> DepthSources(const RenderEvalOptions& options, bool has_exact_depth);

// A file name stem for --dump from the case's names.
std::string DumpName(const std::string& dataset, const std::string& viewpoint, EvalDepth depth);

// Renders `camera` at `pose` (once to warm up, once timed) and scores it against `truth`;
// `truth_depth_m` (may be empty) tells where the depth edges and the cracks are. `render` (may be
// null) receives the rendered image.
StatusOr<RenderEvalCase> RenderAndScore(CpuSceneRenderer& renderer,
                                        const CameraModel& camera,
                                        const Rigid3& pose,
                                        const cv::Mat& truth,
                                        const cv::Mat& truth_depth_m,
                                        int num_sources,
                                        const RenderEvalOptions& options,
                                        const std::string& dump_name,
                                        cv::Mat* render = nullptr);

// RenderAndScore for one case, labelled: its dataset, viewpoint and depth source set, its dump
// files named from them.
struct CaseLabel {
  std::string dataset;
  std::string viewpoint;
  EvalDepth depth = EvalDepth::kDepthStage;
};
StatusOr<RenderEvalCase> RenderCase(CpuSceneRenderer& renderer,
                                    const CameraModel& camera,
                                    const Rigid3& pose,
                                    const cv::Mat& truth,
                                    const cv::Mat& truth_depth_m,
                                    int num_sources,
                                    const RenderEvalOptions& options,
                                    const CaseLabel& label);

Rigid3 PoseAt(const Eigen::Vector3d& centre_in_world, const Eigen::Quaterniond& cam_from_world_rotation);

// A simulated scene on a lattice at options.sim_scale, without distortion: the clean views (rig
// frame = world) and their exact depth.
struct SimLattice {
  sim::Scene scene;
  SimCameraSpec spec;
  std::string dataset;  // "sim one_face 3x3"
  std::vector<View> views;
  std::vector<DepthMap> depths;
};
StatusOr<SimLattice> RenderSimLattice(const std::filesystem::path& scene_file,
                                      const SimCameraSpec& lattice,
                                      const RenderEvalOptions& options);

// MakeRenderer over `lattice`'s views (the depth stage over its nominal range, as in the product),
// the step reported to options.progress under `dataset`.
StatusOr<std::unique_ptr<CpuSceneRenderer>> MakeSimLatticeRenderer(const SimLattice& lattice,
                                                                   EvalDepth source,
                                                                   const std::string& dataset,
                                                                   const RenderEvalOptions& options);

}  // namespace px::eval
