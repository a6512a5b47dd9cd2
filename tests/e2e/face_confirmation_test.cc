// A face found on the centre view is looked for again in the other views (face_confirmation.h):
// the simulator's face card, seen by three lenses of a Pop9, is found again; the same face pasted
// into the centre view alone (a pattern only one view sees, as a face-like texture is to the
// cascades) is not. Needs the face photos of ../shared/data (the scene's texture) and opencv-data.
#include "pipeline/direct/face_confirmation.h"

#include <gtest/gtest.h>

#include "device/face_cascades.h"
#include "pipeline/direct/subjects.h"
#include "sim/synthetic/data_paths.h"
#include "sim/synthetic/ray_caster.h"
#include "sim/synthetic/scene_json.h"
#include "sim/synthetic/sim_camera.h"

namespace px {
namespace {

struct FaceViews {
  std::vector<View> views;  // the centre lens first, then its left and right neighbours
  std::vector<DepthMap> depths;
};

// The scene seen by the Pop9's centre lens and the lenses beside it, with true depth.
StatusOr<FaceViews> RenderFaceViews(const std::string& scene_name) {
  PX_ASSIGN_OR_RETURN(sim::Scene scene, sim::LoadScene(sim::ScenesDir() / (scene_name + ".json")));
  if (!scene.warnings.empty()) return FailedPreconditionError(scene.warnings.front());
  const SimCameraSpec spec = SimCameraSpec::Pop9();
  const RigCalibration rig = spec.Calibration();
  sim::RenderOptions render;
  render.supersampling = spec.supersampling;
  FaceViews out;
  for (const int lens_index : {4, 3, 5}) {
    const LensCalibration& lens = rig.lenses[lens_index];
    PX_ASSIGN_OR_RETURN(sim::RenderedView rendered, sim::RenderView(scene, lens.camera, lens.cam_from_rig, render));
    View view;
    view.id = ViewId{lens_index};
    view.image = rendered.bgr;
    view.camera = lens.camera;
    view.cam_from_world = lens.cam_from_rig;
    out.views.push_back(view);
    out.depths.push_back(DepthMap{view.id, rendered.depth_m, cv::Mat(rendered.depth_m.size(), CV_32F, cv::Scalar(1))});
  }
  return out;
}

class FaceConfirmationTest : public ::testing::Test {
 protected:
  void SetUp() override {
    StatusOr<std::shared_ptr<const direct::FaceDetector>> detector = device::LoadFaceDetector();
    if (!detector.ok()) GTEST_SKIP() << detector.status().message();
    detector_ = *detector;
    StatusOr<FaceViews> views = RenderFaceViews("one_face");
    if (!views.ok()) GTEST_SKIP() << "one_face scene: " << views.status().message() << " (PX_DATA_DIR)";
    scene_ = *views;
  }

  // The largest face the detector finds on views[0], as a subject at its true depth.
  Subject CentreFace(const std::vector<View>& views) const {
    const std::vector<direct::FaceBox> faces = detector_->Detect(views[0].image, FaceDetectionOptions{});
    EXPECT_FALSE(faces.empty());
    if (faces.empty()) return Subject{};
    StatusOr<Subject> subject = direct::SubjectFromBox(views[0], &scene_.depths[0], faces[0].box, "face");
    EXPECT_TRUE(subject.ok()) << subject.status().ToString();
    return subject.ok() ? *subject : Subject{};
  }

  std::shared_ptr<const direct::FaceDetector> detector_;
  FaceViews scene_;
};

TEST_F(FaceConfirmationTest, AFaceEveryViewSeesIsFoundAgain) {
  const Subject face = CentreFace(scene_.views);
  ASSERT_TRUE(face.depth_known);
  const direct::FaceConfirmation confirmation =
      direct::ConfirmFace(face, scene_.views, 0, *detector_, FaceDetectionOptions{});
  EXPECT_GE(confirmation.views_checked, 1) << confirmation.detail;
  EXPECT_EQ(confirmation.confirming_view, 3) << confirmation.detail;  // the nearest first (a tie: the first)
  EXPECT_FALSE(confirmation.Refuted());
}

TEST_F(FaceConfirmationTest, AFaceOnlyOneViewSeesIsRefuted) {
  // The other views see the scene without the face: its card painted over with the wall beside it.
  std::vector<View> views = scene_.views;
  const Subject face = CentreFace(views);
  for (size_t i = 1; i < views.size(); ++i) {
    cv::Mat image = views[i].image.clone();
    const cv::Rect card(static_cast<int>(face.box_px.x) - 40,
                        static_cast<int>(face.box_px.y) - 40,
                        static_cast<int>(face.box_px.width) + 80,
                        static_cast<int>(face.box_px.height) + 80);
    image(card & cv::Rect(0, 0, image.cols, image.rows)).setTo(cv::mean(image(cv::Rect(0, 0, 40, 40))));
    views[i].image = image;
  }
  const direct::FaceConfirmation confirmation = direct::ConfirmFace(face, views, 0, *detector_, FaceDetectionOptions{});
  EXPECT_EQ(confirmation.views_checked, 2) << confirmation.detail;
  EXPECT_EQ(confirmation.confirming_view, -1) << confirmation.detail;
  EXPECT_TRUE(confirmation.Refuted());
}

TEST_F(FaceConfirmationTest, NoOtherViewToLookInLeavesTheFaceStanding) {
  const Subject face = CentreFace(scene_.views);
  const std::vector<View> alone = {scene_.views[0]};
  const direct::FaceConfirmation confirmation = direct::ConfirmFace(face, alone, 0, *detector_, FaceDetectionOptions{});
  EXPECT_EQ(confirmation.views_checked, 0);
  EXPECT_FALSE(confirmation.Refuted());
}

}  // namespace
}  // namespace px
