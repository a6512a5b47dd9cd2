// The simulator's ground truth must be geometrically self-consistent: a point seen in one lens,
// placed in 3D with that lens's depth, must reappear in every other lens where it is visible,
// with the depth and (these scenes are Lambertian) the colour that lens recorded. Checked on
// both lattice presets, with and without lens distortion.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "pipeline/core/order_statistics.h"
#include "sim/synthetic/scene_json.h"
#include "sim/synthetic/sim_sensor.h"
#include "sim/synthetic/sim_test_util.h"

namespace px::sim {
namespace {

struct Case {
  std::string name;
  SimCameraSpec spec;
};

void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

SimCameraSpec Distorted(SimCameraSpec spec) {
  spec.distortion = {-0.12, 0.03, 0.0008, -0.0005, 0.0};  // mild barrel, as on small lenses
  return spec;
}

// Lenses moved off the factory calibration (default magnitudes): the views follow the true lenses.
SimCameraSpec Perturbed(SimCameraSpec spec) {
  spec.perturb_lenses_seed = 4;
  return spec;
}

template <typename T>
T Bilinear(const cv::Mat& image, double x, double y) {
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const float ax = static_cast<float>(x - x0), ay = static_cast<float>(y - y0);
  const T a = image.at<T>(y0, x0), b = image.at<T>(y0, x0 + 1);
  const T c = image.at<T>(y0 + 1, x0), d = image.at<T>(y0 + 1, x0 + 1);
  return (a * (1 - ax) + b * ax) * (1 - ay) + (c * (1 - ax) + d * ax) * ay;
}

struct Agreement {
  int projected = 0;                     // samples landing inside view j
  int visible = 0;                       // ... where j's four neighbouring depths agree within 2%
  std::vector<double> depth_rel_errors;  // |interpolated j depth - expected| / expected, visible
  std::vector<double> colour_errors;     // mean |BGR_i - interpolated BGR_j| over channels, visible

  void Add(const Agreement& other) {
    projected += other.projected;
    visible += other.visible;
    depth_rel_errors.insert(depth_rel_errors.end(), other.depth_rel_errors.begin(), other.depth_rel_errors.end());
    colour_errors.insert(colour_errors.end(), other.colour_errors.begin(), other.colour_errors.end());
  }
};

// Projects every `step`-th pixel of view i into view j. `j_offset_m` displaces view j, to show
// that the comparison notices a wrong geometry.
Agreement Compare(
    const ViewTruth& vi, const ViewTruth& vj, const cv::Mat& vj_bgr_f, const Eigen::Vector3d& j_offset_m, int step) {
  Agreement result;
  cv::Mat inverse_depth_j;
  cv::divide(1.0, vj.depth_m, inverse_depth_j, CV_32F);
  const Rigid3 world_from_i = vi.cam_from_rig.Inverse();
  Rigid3 j_from_world = vj.cam_from_rig;
  j_from_world.translation += j_offset_m;
  const int w = vj.camera.width, h = vj.camera.height;
  for (int y = step / 2; y < vi.camera.height; y += step) {
    for (int x = step / 2; x < vi.camera.width; x += step) {
      const float depth = vi.depth_m.at<float>(y, x);
      if (depth <= 0) continue;
      const Eigen::Vector3d p_in_world = world_from_i * (vi.camera.Unproject(Eigen::Vector2d(x, y)) * depth);
      const Eigen::Vector3d p_in_j = j_from_world * p_in_world;
      Eigen::Vector2d pixel;
      if (!vj.camera.Project(p_in_j, &pixel)) continue;
      if (!(pixel.x() >= 0 && pixel.y() >= 0 && pixel.x() < w - 1 && pixel.y() < h - 1)) continue;
      ++result.projected;
      const int x0 = static_cast<int>(pixel.x()), y0 = static_cast<int>(pixel.y());
      bool visible = true;
      for (int dy = 0; dy <= 1; ++dy) {
        for (int dx = 0; dx <= 1; ++dx) {
          const float dj = vj.depth_m.at<float>(y0 + dy, x0 + dx);
          visible = visible && std::abs(dj - p_in_j.z()) < 0.02 * p_in_j.z();
        }
      }
      if (!visible) continue;
      ++result.visible;
      // Inverse depth of a plane is affine in pinhole pixel coordinates, so interpolating 1/z is
      // exact on planes (and close under mild distortion); only curved surfaces leave an error.
      const double interpolated = 1.0 / Bilinear<float>(inverse_depth_j, pixel.x(), pixel.y());
      result.depth_rel_errors.push_back(std::abs(interpolated - p_in_j.z()) / p_in_j.z());
      const cv::Vec3f cj = Bilinear<cv::Vec3f>(vj_bgr_f, pixel.x(), pixel.y());
      const cv::Vec3b ci = vi.bgr.at<cv::Vec3b>(y, x);
      result.colour_errors.push_back((std::abs(ci[0] - cj[0]) + std::abs(ci[1] - cj[1]) + std::abs(ci[2] - cj[2])) / 3);
    }
  }
  return result;
}

class GroundTruthConsistency : public ::testing::TestWithParam<Case> {};

TEST_P(GroundTruthConsistency, EveryViewAgreesWithEveryOther) {
  auto scene = LoadScene(testing::SceneFile("still_life"));
  ASSERT_TRUE(scene.ok()) << scene.status().ToString();
  const SimCameraSpec& spec = GetParam().spec;
  auto views = RenderLatticeViews(*scene, spec);
  ASSERT_TRUE(views.ok()) << views.status().ToString();
  std::vector<cv::Mat> bgr_f(views->size());
  for (size_t j = 0; j < views->size(); ++j) (*views)[j].bgr.convertTo(bgr_f[j], CV_32FC3);

  // ~1500 samples per view pair keeps the test fast and still covers every object.
  const int step = spec.tile_width / 40;
  Agreement all;
  for (size_t i = 0; i < views->size(); ++i) {
    for (size_t j = 0; j < views->size(); ++j) {
      if (i == j) continue;
      all.Add(Compare((*views)[i], (*views)[j], bgr_f[j], Eigen::Vector3d::Zero(), step));
    }
  }
  // Nearly everything a lens sees, its neighbours see too: the scene has few occlusions at
  // these baselines (2.5 cm / 1.2 cm vs objects from 0.85 m). A geometry error (wrong baseline
  // sign, swapped lenses, off-by-one pixel convention) would make most samples "invisible".
  ASSERT_GT(all.projected, 10000);
  EXPECT_GT(static_cast<double>(all.visible) / all.projected, 0.93);

  // Depth. Measured: the median sample agrees to ~3e-8 (float32 storage), 80% (planes and box
  // faces, where interpolating 1/z is exact) to ~1e-6 with distortion (float ray table, 1/z
  // only nearly affine); the rest lie on spheres, where interpolating across one pixel of a
  // curved, steeply slanted surface leaves up to a few 1e-4, and at creases where the four
  // neighbours straddle two surfaces nearer than 2%. A misregistration of 1/10 pixel would
  // already put the 80th percentile near 1e-4 (see the shifted lens below).
  EXPECT_LT(Percentile(all.depth_rel_errors, 0.5), 2e-7);
  EXPECT_LT(Percentile(all.depth_rel_errors, 0.8), 5e-6);
  EXPECT_LT(Percentile(all.depth_rel_errors, 0.95), 2e-4);
  EXPECT_LT(Percentile(all.depth_rel_errors, 0.99), 1e-3);

  // Colour: Lambertian shading, so a point has the same colour in every lens up to resampling
  // a band-limited texture at a sub-pixel offset. Measured: median ~0.35 levels, 90th
  // percentile < 2, 99th 10-16 (texture edges in the photos, object outlines).
  EXPECT_LT(Percentile(all.colour_errors, 0.5), 1.0);
  EXPECT_LT(Percentile(all.colour_errors, 0.9), 4.0);
  EXPECT_LT(Percentile(all.colour_errors, 0.99), 25.0);

  // The comparison has power: moving one lens by 2 mm sideways (0.3-1.3 px of disparity at
  // these depths) breaks the agreement: measured 80th percentiles ~4e-4 in depth and ~2 levels
  // in colour, against ~1e-6 and ~0.7 for the true pose.
  const ViewTruth& centre = (*views)[views->size() / 2];
  const ViewTruth& corner = (*views)[0];
  const Agreement shifted = Compare(centre, corner, bgr_f[0], Eigen::Vector3d(0.002, 0, 0), step);
  const Agreement truthful = Compare(centre, corner, bgr_f[0], Eigen::Vector3d::Zero(), step);
  EXPECT_GT(Percentile(shifted.depth_rel_errors, 0.8), 50 * Percentile(truthful.depth_rel_errors, 0.8));
  EXPECT_GT(Percentile(shifted.depth_rel_errors, 0.8), 1e-4);
  EXPECT_GT(Percentile(shifted.colour_errors, 0.8), 2 * Percentile(truthful.colour_errors, 0.8));
}

INSTANTIATE_TEST_SUITE_P(Lattices,
                         GroundTruthConsistency,
                         ::testing::Values(Case{"pop9", SimCameraSpec::Pop9()},
                                           Case{"pop9_distorted", Distorted(SimCameraSpec::Pop9())},
                                           Case{"integral5x4", SimCameraSpec::Integral5x4()},
                                           Case{"integral5x4_distorted", Distorted(SimCameraSpec::Integral5x4())},
                                           Case{"pop9_perturbed_distorted",
                                                Perturbed(Distorted(SimCameraSpec::Pop9()))}),
                         [](const auto& param_info) { return param_info.param.name; });

// With perturbed lenses the views are rendered through the true lenses, which the factory
// calibration does not describe: the same comparison made with the factory's cameras fails.
TEST(PerturbedLensesTest, ViewsDisagreeWithTheFactoryCalibration) {
  auto scene = LoadScene(testing::SceneFile("still_life"));
  ASSERT_TRUE(scene.ok()) << scene.status().ToString();
  const SimCameraSpec spec = testing::Quartered(Perturbed(SimCameraSpec::Pop9()));
  auto views = RenderLatticeViews(*scene, spec);
  ASSERT_TRUE(views.ok()) << views.status().ToString();
  const RigCalibration factory = spec.Calibration();
  std::vector<ViewTruth> as_factory = *views;
  for (size_t i = 0; i < as_factory.size(); ++i) {
    as_factory[i].camera = factory.lenses[i].camera;
    as_factory[i].cam_from_rig = factory.lenses[i].cam_from_rig;
    EXPECT_FALSE(as_factory[i].camera.fx == (*views)[i].camera.fx) << "lens " << i << " was not perturbed";
  }
  cv::Mat corner_f;
  (*views)[0].bgr.convertTo(corner_f, CV_32FC3);
  const int step = spec.tile_width / 40;
  const Agreement truthful = Compare((*views)[4], (*views)[0], corner_f, Eigen::Vector3d::Zero(), step);
  const Agreement factory_view = Compare(as_factory[4], as_factory[0], corner_f, Eigen::Vector3d::Zero(), step);
  // Up to 0.3 degrees of rotation and 1 % of focal length move points by about a pixel here.
  EXPECT_GT(Percentile(factory_view.depth_rel_errors, 0.8), 20 * Percentile(truthful.depth_rel_errors, 0.8));
  EXPECT_GT(Percentile(factory_view.colour_errors, 0.8), 1.5 * Percentile(truthful.colour_errors, 0.8));
}

TEST(PerturbedLensesTest, DrawsAreSeededAndWithinTheMagnitudes) {
  SimCameraSpec spec = SimCameraSpec::Pop9();
  const RigCalibration factory = spec.Calibration();
  const LensPerturbation magnitudes;
  const RigCalibration a = PerturbLenses(factory, magnitudes, 7);
  const RigCalibration b = PerturbLenses(factory, magnitudes, 7);
  const RigCalibration c = PerturbLenses(factory, magnitudes, 8);
  double max_rotation = 0, max_focal = 0, max_pp = 0, max_centre = 0;
  for (int i = 0; i < factory.NumViews(); ++i) {
    EXPECT_EQ(a.lenses[i].camera.fx, b.lenses[i].camera.fx);
    EXPECT_NE(a.lenses[i].camera.fx, c.lenses[i].camera.fx);
    EXPECT_EQ(a.lenses[i].camera.fy / a.lenses[i].camera.fx, factory.lenses[i].camera.fy / factory.lenses[i].camera.fx);
    max_focal = std::max(max_focal, std::abs(a.lenses[i].camera.fx / factory.lenses[i].camera.fx - 1));
    max_pp = std::max({max_pp,
                       std::abs(a.lenses[i].camera.cx - factory.lenses[i].camera.cx),
                       std::abs(a.lenses[i].camera.cy - factory.lenses[i].camera.cy)});
    max_rotation = std::max(max_rotation, RotationErrorDeg(a.lenses[i].cam_from_rig, factory.lenses[i].cam_from_rig));
    max_centre = std::max(
        max_centre,
        (CameraCentre(a.lenses[i].cam_from_rig) - CameraCentre(factory.lenses[i].cam_from_rig)).cwiseAbs().maxCoeff());
  }
  EXPECT_LE(max_focal, magnitudes.focal_relative);
  EXPECT_GT(max_focal, 0.3 * magnitudes.focal_relative);
  EXPECT_LE(max_pp, magnitudes.principal_point_px);
  EXPECT_LE(max_rotation, std::sqrt(3.0) * magnitudes.rotation_deg);  // up to the limit on each axis
  EXPECT_GT(max_rotation, 0.3 * magnitudes.rotation_deg);
  EXPECT_LE(max_centre, magnitudes.centre_m + 1e-12);
  EXPECT_TRUE(a.Validate().ok());

  spec.perturbation.rotation_deg = -1;
  spec.perturb_lenses_seed = 1;
  const Status invalid = spec.Validate();
  ASSERT_FALSE(invalid.ok());
  EXPECT_NE(invalid.message().find("rotation_deg = -1"), std::string::npos) << invalid.message();
}

}  // namespace
}  // namespace px::sim
