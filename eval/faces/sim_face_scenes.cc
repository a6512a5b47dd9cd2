#include "eval/faces/sim_face_scenes.h"

#include <chrono>
#include <string>
#include <utility>

#include "sim/synthetic/data_paths.h"
#include "sim/synthetic/ray_caster.h"
#include "sim/synthetic/scene_json.h"
#include "sim/synthetic/sim_camera.h"

namespace px::eval {
namespace {

constexpr double kFaceWidthM = 0.17;  // what the scenes scale each labelled face box to

struct FaceScene {
  const char* name;
  std::vector<std::string> face_planes;
};

}  // namespace

StatusOr<std::vector<FaceImageResult>> RunSimFaceScenes(const direct::FaceDetector& detector,
                                                        const FaceDetectionOptions& detection,
                                                        double min_iou) {
  const std::vector<FaceScene> scenes = {{"one_face", {"face"}}, {"two_faces", {"near_face", "far_face"}}};
  const SimCameraSpec spec = SimCameraSpec::Pop9();
  const RigCalibration rig = spec.Calibration();
  const LensCalibration& lens = rig.lenses[rig.NumViews() / 2];
  std::vector<FaceImageResult> results;
  for (const FaceScene& face_scene : scenes) {
    const std::filesystem::path file = sim::ScenesDir() / (std::string(face_scene.name) + ".json");
    PX_ASSIGN_OR_RETURN(sim::Scene scene, sim::LoadScene(file));
    if (!scene.warnings.empty()) {
      return FailedPreconditionError("sim scene " + file.string() + ": " + scene.warnings.front() +
                                     " (the face photos come from ../shared/data)");
    }
    sim::RenderOptions render;
    render.supersampling = spec.supersampling;
    PX_ASSIGN_OR_RETURN(sim::RenderedView view, sim::RenderView(scene, lens.camera, lens.cam_from_rig, render));
    std::vector<cv::Rect2d> truth;
    for (const std::string& plane_name : face_scene.face_planes) {
      const sim::Plane* plane = nullptr;
      for (const sim::Plane& p : scene.planes) {
        if (p.name == plane_name) plane = &p;
      }
      if (plane == nullptr) return NotFoundError("sim scene " + file.string() + ": no plane '" + plane_name + "'");
      const Eigen::Vector3d centre_in_cam = lens.cam_from_rig * plane->centre_m;
      Eigen::Vector2d centre;
      if (!lens.camera.Project(centre_in_cam, &centre)) {
        return FailedPreconditionError("sim scene " + file.string() + ": face '" + plane_name + "' is behind the lens");
      }
      const double side_px = kFaceWidthM * lens.camera.fx / centre_in_cam.z();
      truth.emplace_back(centre.x() - side_px / 2, centre.y() - side_px / 2, side_px, side_px);
    }
    FaceImageResult result;
    result.file = std::string("sim/") + face_scene.name;
    result.size = view.bgr.size();
    const auto start = std::chrono::steady_clock::now();
    for (const direct::FaceBox& face : detector.Detect(view.bgr, detection)) result.detections.push_back(face.box);
    result.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    result.match = MatchFaces(truth, result.detections, min_iou);
    results.push_back(std::move(result));
  }
  return results;
}

}  // namespace px::eval
