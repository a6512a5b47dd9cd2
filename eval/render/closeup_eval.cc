#include "eval/render/closeup_eval.h"

#include <algorithm>
#include <array>
#include <memory>

#include "eval/render/render_eval_steps.h"
#include "sim/synthetic/ray_caster.h"

namespace px::eval {
namespace {

// One end of a recorded move, in the rig frame (metres), focal length in 640x480 output pixels.
struct RecordedEnd {
  std::array<double, 3> centre_in_world_m;
  std::array<double, 4> cam_from_world_wxyz;
  double focal_px;
};

struct RecordedMove {
  const char* scene;
  RecordedEnd start, end;
};

// The dolly in `parallax clip` planned at commit e36e5f2 on `parallax sim --scene <scene>` (Pop9,
// 640x480, seed 1), read from the clip's JSON (camera_path.keyframes). one_face: its automatic
// move (the demo's), ending 0.72 m forward aimed at the face at 1.5f (re-framed to 1.36f to keep
// the face in). two_faces: `--move dolly_in`, on the second face, ending 0.41 m forward.
constexpr std::array<RecordedMove, 2> kDollyIns = {{
    {"one_face",
     {{0.013636363636363641, -0.031818181818181815, -0.0838903833925724},
      {0.9999866022843902, 0.004465599893016866, 0.0026179252553134138, 1.1690763369576623e-05},
      560.0},
     {{-0.05, 0.05, 0.7170458793640135},
      {0.9969962336072915, -0.05932665743467074, -0.04970021621273254, 0.0029574311339307037},
      763.9151094658437}},
    {"two_faces",
     {{0.022727272727272735, -0.02272727272727273, -0.09352012872695924},
      {0.9999910968909577, 0.002614707225806438, 0.003312003917136748, 8.659997674940291e-06},
      560.0},
     {{-0.03772727272727273, 0.03772727272727273, 0.405105524612353},
      {0.9968335200843249, -0.04230586650221541, -0.06726809485068073, 0.002854874944785691},
      703.9878313052169}},
}};

CameraKeyframe Keyframe(const RecordedEnd& end, double t, double scale) {
  CameraKeyframe key;
  key.t = t;
  key.centre_in_world = Eigen::Vector3d(end.centre_in_world_m[0], end.centre_in_world_m[1], end.centre_in_world_m[2]);
  key.cam_from_world_rotation = Eigen::Quaterniond(end.cam_from_world_wxyz[0],
                                                   end.cam_from_world_wxyz[1],
                                                   end.cam_from_world_wxyz[2],
                                                   end.cam_from_world_wxyz[3])
                                    .normalized();
  key.focal_px = end.focal_px * scale;
  return key;
}

}  // namespace

std::vector<std::string> CloseUpScenes() {
  std::vector<std::string> scenes;
  for (const RecordedMove& move : kDollyIns) scenes.emplace_back(move.scene);
  return scenes;
}

StatusOr<CameraPath> RecordedDollyIn(const std::string& scene, const CameraModel& source_camera, double scale) {
  const auto move =
      std::find_if(kDollyIns.begin(), kDollyIns.end(), [&](const RecordedMove& m) { return scene == m.scene; });
  if (move == kDollyIns.end()) {
    return InvalidArgumentError("eval render: no recorded dolly in for scene '" + scene + "' (close-ups exist for " +
                                "one_face and two_faces)");
  }
  CameraPath path = BlankPath(PathKind::kNovelView, "dolly_in", source_camera, 30, 5);
  path.keyframes = {Keyframe(move->start, 0, scale), Keyframe(move->end, 1, scale)};
  PX_RETURN_IF_ERROR(path.Validate().WithContext("eval render: recorded dolly in of " + scene));
  return path;
}

StatusOr<std::vector<RenderEvalCase>> EvaluateSimulatedCloseUps(const std::filesystem::path& scene_file,
                                                                const RenderEvalOptions& options) {
  PX_RETURN_IF_ERROR(options.Validate());
  const std::string stem = scene_file.stem().string();
  const std::vector<std::string> scenes = CloseUpScenes();
  if (std::find(scenes.begin(), scenes.end(), stem) == scenes.end()) {
    return InvalidArgumentError("eval render: no recorded dolly in for scene '" + stem + "' (close-ups exist for " +
                                "one_face and two_faces)");
  }
  PX_ASSIGN_OR_RETURN(SimLattice lattice, RenderSimLattice(scene_file, SimCameraSpec::Pop9(), options));
  const std::string dataset = lattice.dataset + " close-up";
  PX_ASSIGN_OR_RETURN(const CameraPath path, RecordedDollyIn(stem, lattice.views.front().camera, options.sim_scale));

  struct Viewpoint {
    std::string name;
    VirtualCamera camera;
    sim::RenderedView truth;
  };
  std::vector<Viewpoint> viewpoints;
  sim::RenderOptions truth_options;
  truth_options.supersampling = lattice.spec.supersampling;
  for (const auto& [name, t] : {std::pair<const char*, double>{"dolly in, halfway", 0.5},
                                std::pair<const char*, double>{"dolly in, close-up end", 1.0}}) {
    Viewpoint viewpoint;
    viewpoint.name = name;
    viewpoint.camera = path.FrameAt(t);
    PX_ASSIGN_OR_RETURN(
        viewpoint.truth,
        sim::RenderView(lattice.scene, viewpoint.camera.camera, viewpoint.camera.cam_from_world, truth_options));
    viewpoints.push_back(std::move(viewpoint));
  }
  std::vector<RenderEvalCase> cases;
  for (EvalDepth source : DepthSources(options, true)) {
    PX_ASSIGN_OR_RETURN(std::unique_ptr<CpuSceneRenderer> renderer,
                        MakeSimLatticeRenderer(lattice, source, dataset, options));
    for (const Viewpoint& viewpoint : viewpoints) {
      Progress(options, dataset + ": " + viewpoint.name);
      PX_ASSIGN_OR_RETURN(RenderEvalCase result,
                          RenderCase(*renderer,
                                     viewpoint.camera.camera,
                                     viewpoint.camera.cam_from_world,
                                     viewpoint.truth.bgr,
                                     viewpoint.truth.depth_m,
                                     static_cast<int>(lattice.views.size()),
                                     options,
                                     {dataset, viewpoint.name, source}));
      cases.push_back(result);
    }
  }
  return cases;
}

}  // namespace px::eval
