// A face too large for the frame (a close-up whose face touches the frame's edges, as on a film
// camera's lens tile) is found: the simulator's face card seen from so close that its labelled
// face box is 1.3 times the 640x480 frame's height. Needs the face photos of ../shared/data and
// opencv-data.
#include <gtest/gtest.h>

#include "device/face_cascades.h"
#include "sim/synthetic/data_paths.h"
#include "sim/synthetic/ray_caster.h"
#include "sim/synthetic/scene_json.h"
#include "sim/synthetic/sim_camera.h"

namespace px {
namespace {

constexpr double kFaceWidthM = 0.17;  // what the scene scales its labelled face box to

TEST(FaceCloseUpTest, AFaceTallerThanTheFrameIsFound) {
  StatusOr<std::shared_ptr<const direct::FaceDetector>> detector = device::LoadFaceDetector();
  if (!detector.ok()) GTEST_SKIP() << detector.status().message();
  StatusOr<sim::Scene> scene = sim::LoadScene(sim::ScenesDir() / "one_face.json");
  ASSERT_TRUE(scene.ok()) << scene.status().ToString();
  if (!scene->warnings.empty()) GTEST_SKIP() << scene->warnings.front() << " (PX_DATA_DIR)";
  const sim::Plane* face = nullptr;
  for (const sim::Plane& plane : scene->planes) {
    if (plane.name == "face") face = &plane;
  }
  ASSERT_NE(face, nullptr);

  const SimCameraSpec spec = SimCameraSpec::Pop9();
  const CameraModel camera = spec.Calibration().lenses[4].camera;
  // Square on to the card, its labelled face box 1.3 times the frame's height: unpadded, the
  // cascades find only a 336 px patch 120 px off the face's centre (one cascade); padded, three
  // agree on a box of 580x463.
  const double face_px = 1.3 * camera.height;
  const double distance = kFaceWidthM * camera.fx / face_px;
  const Eigen::Vector3d centre = face->centre_m - Eigen::Vector3d(0, 0, distance);
  const Rigid3 cam_from_world(Eigen::Quaterniond::Identity(), -centre);
  sim::RenderOptions render;
  render.supersampling = spec.supersampling;
  StatusOr<sim::RenderedView> view = sim::RenderView(*scene, camera, cam_from_world, render);
  ASSERT_TRUE(view.ok()) << view.status().ToString();

  const std::vector<direct::FaceBox> faces = (*detector)->Detect(view->bgr, FaceDetectionOptions{});
  ASSERT_FALSE(faces.empty()) << "no face in a close-up whose face is " << face_px << " px tall";
  const direct::FaceBox& largest = faces.front();
  const cv::Rect2d frame(0, 0, camera.width, camera.height);
  EXPECT_EQ((largest.box & frame).area(), largest.box.area()) << "the box stays inside the frame";
  EXPECT_GT(largest.box.height, 0.7 * camera.height);
  EXPECT_GE(largest.cascades, 2);
  Eigen::Vector2d face_centre;
  ASSERT_TRUE(camera.Project(cam_from_world * face->centre_m, &face_centre));
  const double cx = largest.box.x + 0.5 * largest.box.width, cy = largest.box.y + 0.5 * largest.box.height;
  EXPECT_LT(std::hypot(cx - face_centre.x(), cy - face_centre.y()), 0.1 * face_px)
      << "box centre (" << cx << ", " << cy << "), face centre " << face_centre.transpose();
}

}  // namespace
}  // namespace px
