#include "eval/render/pan_eval.h"

#include <memory>
#include <string>

#include "eval/render/image_metrics.h"
#include "eval/render/render_eval_steps.h"
#include "sim/synthetic/ray_caster.h"

namespace px::eval {
namespace {

// Per-frame figures averaged over a sequence (PSNRs in dB, as the other groups' means).
RenderEvalCase MeanOverFrames(const std::vector<RenderEvalCase>& frames) {
  double RenderEvalCase::*const fields[] = {&RenderEvalCase::psnr_db,
                                            &RenderEvalCase::ssim,
                                            &RenderEvalCase::psnr_covered_edges_db,
                                            &RenderEvalCase::psnr_covered_flat_db,
                                            &RenderEvalCase::psnr_holes_db,
                                            &RenderEvalCase::hole_ratio,
                                            &RenderEvalCase::hole_score,
                                            &RenderEvalCase::crack_fraction,
                                            &RenderEvalCase::render_ms};
  RenderEvalCase mean = frames.front();
  for (double RenderEvalCase::*field : fields) {
    mean.*field = 0;
    for (const RenderEvalCase& frame : frames) mean.*field += frame.*field / static_cast<double>(frames.size());
  }
  return mean;
}

}  // namespace

StatusOr<std::vector<RenderEvalCase>> EvaluateSimulatedPan(const std::filesystem::path& scene_file,
                                                           const SimCameraSpec& spec,
                                                           const RenderEvalOptions& options) {
  PX_RETURN_IF_ERROR(options.Validate());
  PX_ASSIGN_OR_RETURN(SimLattice lattice, RenderSimLattice(scene_file, spec, options));
  const std::string dataset = lattice.dataset + " pan";
  const std::string viewpoint = "on the lattice plane, " + std::to_string(kPanFrames) + " frames";
  const double b = lattice.spec.baseline_m;
  const CameraModel& camera = lattice.views.front().camera;
  std::vector<Rigid3> poses;
  for (int k = 0; k < kPanFrames; ++k) {
    const double x = (0.1 + 0.4 * k / (kPanFrames - 1)) * b;
    poses.push_back(PoseAt(Eigen::Vector3d(x, 0.3 * b, 0), Eigen::Quaterniond::Identity()));
  }
  Progress(options, dataset + ": ray casting " + std::to_string(kPanFrames) + " frames");
  sim::RenderOptions truth_options;
  truth_options.supersampling = lattice.spec.supersampling;
  std::vector<sim::RenderedView> truths;
  std::vector<cv::Mat> truth_images;  // the same images, as TemporalPsnr takes them
  for (const Rigid3& pose : poses) {
    PX_ASSIGN_OR_RETURN(sim::RenderedView truth, sim::RenderView(lattice.scene, camera, pose, truth_options));
    truth_images.push_back(truth.bgr);
    truths.push_back(std::move(truth));
  }
  std::vector<RenderEvalCase> cases;
  for (EvalDepth source : DepthSources(options, true)) {
    PX_ASSIGN_OR_RETURN(std::unique_ptr<CpuSceneRenderer> renderer,
                        MakeSimLatticeRenderer(lattice, source, dataset, options));
    std::vector<RenderEvalCase> frames;
    std::vector<cv::Mat> renders(poses.size());
    for (size_t k = 0; k < poses.size(); ++k) {
      PX_ASSIGN_OR_RETURN(RenderEvalCase frame,
                          RenderAndScore(*renderer,
                                         camera,
                                         poses[k],
                                         truths[k].bgr,
                                         truths[k].depth_m,
                                         static_cast<int>(lattice.views.size()),
                                         options,
                                         DumpName(dataset, viewpoint + " " + std::to_string(k), source),
                                         &renders[k]));
      frames.push_back(frame);
    }
    RenderEvalCase result = MeanOverFrames(frames);
    result.temporal_psnr_db = TemporalPsnr(renders, truth_images);
    result.dataset = dataset;
    result.viewpoint = viewpoint;
    result.depth = source;
    cases.push_back(result);
  }
  return cases;
}

}  // namespace px::eval
