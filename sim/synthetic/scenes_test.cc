// The shipped scenes (sim/scenes/*.json): they load, fill the lenses' views at the intended
// depths, and the face scenes show faces that a standard detector finds.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <opencv2/imgproc.hpp>
#include <opencv2/objdetect.hpp>

#include "sim/synthetic/data_paths.h"
#include "sim/synthetic/ray_caster.h"
#include "sim/synthetic/scene_json.h"
#include "sim/synthetic/sim_sensor.h"
#include "sim/synthetic/sim_test_util.h"

namespace px::sim {
namespace {

using testing::SceneFile;

constexpr char kCascade[] = "/usr/share/opencv4/haarcascades/haarcascade_frontalface_default.xml";
constexpr double kFaceWidthM = 0.17;  // what the scenes size the labelled face boxes to

bool FaceDataPresent() {
  return std::filesystem::exists(SharedDataDir() / "faces_dlib_pascalvoc" / "2008_001322.jpg") &&
         std::filesystem::exists(SharedDataDir() / "faces_dlib_pascalvoc" / "2008_001009.jpg");
}

Scene MustLoad(const std::string& name) {
  auto scene = LoadScene(SceneFile(name));
  EXPECT_TRUE(scene.ok()) << scene.status().ToString();
  return scene.ok() ? *scene : Scene();
}

TEST(ScenesTest, AllLoadAndWarnOnlyWithoutData) {
  for (const char* name : {"still_life", "one_face", "two_faces"}) {
    const Scene scene = MustLoad(name);
    EXPECT_EQ(scene.name, name);
    if (std::filesystem::exists(SharedDataDir())) {
      EXPECT_TRUE(scene.warnings.empty()) << name << ": " << (scene.warnings.empty() ? "" : scene.warnings[0]);
    }
  }
}

TEST(ScenesTest, StillLifeFillsEveryLensAtSeveralDepths) {
  const Scene scene = MustLoad("still_life");
  for (SimCameraSpec spec : {SimCameraSpec::Pop9(), SimCameraSpec::Integral5x4()}) {
    spec = testing::Quartered(spec);  // same field of view, a quarter of the rays
    spec.supersampling = 1;
    spec.distortion = {-0.12, 0.03, 0, 0, 0};  // barrel distortion widens the view: still filled
    auto views = RenderLatticeViews(scene, spec);
    ASSERT_TRUE(views.ok()) << views.status().ToString();
    for (const ViewTruth& view : *views) {
      EXPECT_EQ(cv::countNonZero(view.depth_m <= 0), 0) << spec.name << " view " << view.id.value;
      double min_depth, max_depth;
      cv::minMaxLoc(view.depth_m, &min_depth, &max_depth);
      EXPECT_LT(min_depth, 1.0) << spec.name << " view " << view.id.value;
      EXPECT_GT(max_depth, 3.5) << spec.name << " view " << view.id.value;
      // Texture everywhere: few flat patches (stereo needs gradients). Measured ~2% of pixels
      // have a Sobel gradient below 1 level/px on this scene.
      cv::Mat gray, gx, gy, magnitude;
      cv::cvtColor(view.bgr, gray, cv::COLOR_BGR2GRAY);
      cv::Sobel(gray, gx, CV_32F, 1, 0, 3, 0.125);
      cv::Sobel(gray, gy, CV_32F, 0, 1, 3, 0.125);
      cv::magnitude(gx, gy, magnitude);
      EXPECT_LT(cv::countNonZero(magnitude < 0.25), static_cast<int>(gray.total() / 10)) << spec.name;
    }
  }
}

// Renders the centre lens of the full-size Pop9 and runs OpenCV's Haar face detector on it.
// Each face plane's centre is its labelled face box's centre (the crops are centred on it).
void ExpectFacesFound(const std::string& scene_name, const std::vector<std::string>& face_planes) {
  if (!FaceDataPresent()) GTEST_SKIP() << "face photos not found under " << SharedDataDir() << " (PX_DATA_DIR)";
  if (!std::filesystem::exists(kCascade)) GTEST_SKIP() << kCascade << " not installed (opencv-data)";
  const Scene scene = MustLoad(scene_name);
  ASSERT_TRUE(scene.warnings.empty());
  const SimCameraSpec spec = SimCameraSpec::Pop9();
  const RigCalibration rig = spec.Calibration();
  const LensCalibration& lens = rig.lenses[rig.NumViews() / 2];
  RenderOptions options;
  options.supersampling = spec.supersampling;
  auto view = RenderView(scene, lens.camera, lens.cam_from_rig, options);
  ASSERT_TRUE(view.ok());

  cv::CascadeClassifier cascade;
  ASSERT_TRUE(cascade.load(kCascade));
  cv::Mat gray;
  cv::cvtColor(view->bgr, gray, cv::COLOR_BGR2GRAY);
  cv::equalizeHist(gray, gray);
  std::vector<cv::Rect> faces;
  cascade.detectMultiScale(gray, faces, 1.1, 3, 0, cv::Size(24, 24));

  for (const std::string& name : face_planes) {
    const Plane* plane = nullptr;
    for (const Plane& p : scene.planes) {
      if (p.name == name) plane = &p;
    }
    ASSERT_NE(plane, nullptr) << name;
    Eigen::Vector2d centre;
    const Eigen::Vector3d centre_in_cam = lens.cam_from_rig * plane->centre_m;
    ASSERT_TRUE(lens.camera.Project(centre_in_cam, &centre));
    const double width_px = kFaceWidthM * lens.camera.fx / centre_in_cam.z();
    // A detection centred within a third of a face width of the labelled centre, of about the
    // right size (Haar boxes run ~0.7-1.4x a dlib box).
    bool found = false;
    for (const cv::Rect& face : faces) {
      const double dx = face.x + face.width * 0.5 - centre.x(), dy = face.y + face.height * 0.5 - centre.y();
      found =
          found || (std::hypot(dx, dy) < width_px / 3 && face.width > 0.6 * width_px && face.width < 1.6 * width_px);
    }
    EXPECT_TRUE(found) << scene_name << ": no face near " << centre.transpose() << " (~" << width_px
                       << " px wide) among " << ::testing::PrintToString(faces);
  }
  // And nothing else looks like a face: the stages that frame faces must not chase textures.
  EXPECT_EQ(faces.size(), face_planes.size()) << scene_name << ": " << ::testing::PrintToString(faces);
}

TEST(ScenesTest, HaarFindsTheFaceInOneFace) { ExpectFacesFound("one_face", {"face"}); }

TEST(ScenesTest, HaarFindsBothFacesInTwoFaces) { ExpectFacesFound("two_faces", {"near_face", "far_face"}); }

TEST(ScenesTest, FaceScenesRenderWithoutTheData) {
  testing::TempDir empty;
  const char* old = std::getenv("PX_DATA_DIR");
  const std::string saved = old ? old : "";
  setenv("PX_DATA_DIR", empty.path().c_str(), 1);
  auto one = LoadScene(SceneFile("one_face"));
  auto two = LoadScene(SceneFile("two_faces"));
  if (old)
    setenv("PX_DATA_DIR", saved.c_str(), 1);
  else
    unsetenv("PX_DATA_DIR");
  ASSERT_TRUE(one.ok()) << one.status().ToString();
  ASSERT_TRUE(two.ok()) << two.status().ToString();
  EXPECT_EQ(one->warnings.size(), 1u);
  EXPECT_EQ(two->warnings.size(), 2u);
  ASSERT_FALSE(one->warnings.empty());
  EXPECT_NE(one->warnings[0].find("2008_001009.jpg"), std::string::npos) << one->warnings[0];
  auto view = RenderView(*one, CameraModel::Pinhole(64, 48, 56), Rigid3());
  ASSERT_TRUE(view.ok());
  EXPECT_EQ(cv::countNonZero(view->depth_m <= 0), 0);
}

}  // namespace
}  // namespace px::sim
