#include "sim/synthetic/sim_sensor.h"

#include <gtest/gtest.h>

#include <cstring>

#include "sim/synthetic/scene_json.h"
#include "sim/synthetic/sim_test_util.h"

namespace px::sim {
namespace {

using testing::Quartered;
using testing::SceneFile;

Scene StillLife() {
  auto scene = LoadScene(SceneFile("still_life"));
  EXPECT_TRUE(scene.ok()) << scene.status().ToString();
  return scene.ok() ? *scene : Scene();
}

// An unlit flat grey wall filling every view: every clean pixel is exactly 200.
Scene FlatWall() {
  auto scene = ParseScene(R"({"materials": {"g": {"type": "flat", "rgb": [200, 200, 200], "lit": false}},
      "objects": [{"type": "plane", "centre_m": [0, 0, 2], "normal": [0, 0, -1], "width_m": 50, "height_m": 50,
                   "material": "g"}]})",
                          ".",
                          "flat wall");
  EXPECT_TRUE(scene.ok()) << scene.status().ToString();
  return *scene;
}

// Small and quick: the Pop9 geometry at 160x120 per tile, one ray per pixel.
SimCameraSpec SmallPop9() {
  SimCameraSpec spec = Quartered(Quartered(SimCameraSpec::Pop9()));
  spec.supersampling = 1;
  return spec;
}

cv::Mat Decode(const RawImage& raw) {
  auto bgr = ToBgr(raw);
  EXPECT_TRUE(bgr.ok()) << bgr.status().ToString();
  return bgr.ok() ? *bgr : cv::Mat();
}

TEST(SimCameraSpecTest, PresetsMatchTheirDescription) {
  const SimCameraSpec pop9 = SimCameraSpec::Pop9();
  EXPECT_TRUE(pop9.Validate().ok()) << pop9.Validate().ToString();
  EXPECT_EQ(pop9.rows, 3);
  EXPECT_EQ(pop9.cols, 3);
  EXPECT_EQ(pop9.tile_width, 640);
  EXPECT_EQ(pop9.tile_height, 480);
  EXPECT_EQ(pop9.gap_px, 16);
  EXPECT_DOUBLE_EQ(pop9.baseline_m, 0.025);
  EXPECT_DOUBLE_EQ(pop9.focal_px, 560);
  EXPECT_EQ(pop9.orientation, TileOrientation::kRotated180);
  EXPECT_EQ(pop9.pixel_format, PixelFormat::kRgb888);
  const LatticeLayout layout = pop9.Layout();
  EXPECT_EQ(layout.sensor_width, 3 * 640 + 4 * 16);
  EXPECT_EQ(layout.sensor_height, 3 * 480 + 4 * 16);

  const SimCameraSpec integral = SimCameraSpec::Integral5x4();
  EXPECT_TRUE(integral.Validate().ok()) << integral.Validate().ToString();
  EXPECT_EQ(integral.cols, 5);
  EXPECT_EQ(integral.rows, 4);
  EXPECT_EQ(integral.tile_width, 320);
  EXPECT_EQ(integral.tile_height, 240);
  EXPECT_DOUBLE_EQ(integral.baseline_m, 0.012);
  EXPECT_DOUBLE_EQ(integral.focal_px, 280);
}

TEST(SimCameraSpecTest, CalibrationPlacesLensesOnTheCentredLattice) {
  const RigCalibration rig = SimCameraSpec::Integral5x4().Calibration();
  ASSERT_TRUE(rig.Validate().ok()) << rig.Validate().ToString();
  ASSERT_EQ(rig.NumViews(), 20);
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 5; ++c) {
      const LensCalibration& lens = rig.lenses[r * 5 + c];
      const Eigen::Vector3d centre = CameraCentre(lens.cam_from_rig);
      EXPECT_NEAR(centre.x(), (c - 2.0) * 0.012, 1e-12);
      EXPECT_NEAR(centre.y(), (r - 1.5) * 0.012, 1e-12);
      EXPECT_NEAR(centre.z(), 0.0, 1e-12);
      EXPECT_NEAR(RotationErrorDeg(lens.cam_from_rig, Rigid3()), 0.0, 1e-9);  // optical axis +z
      EXPECT_DOUBLE_EQ(lens.camera.fx, 280);
      EXPECT_DOUBLE_EQ(lens.camera.cx, 159.5);
    }
  }
}

TEST(SimCameraSpecTest, ValidateNamesTheBadField) {
  SimCameraSpec spec;
  spec.rows = 0;
  EXPECT_NE(spec.Validate().message().find("rows"), std::string::npos) << spec.Validate().ToString();
  spec = SimCameraSpec();
  spec.vignetting = 1.5;
  EXPECT_NE(spec.Validate().message().find("vignetting"), std::string::npos);
  spec = SimCameraSpec();
  spec.supersampling = 0;
  EXPECT_NE(spec.Validate().message().find("supersampling"), std::string::npos);
  // NV12 needs an even sensor: 3 x 641 + 4 x 16 = 1987 columns is not.
  spec = SimCameraSpec();
  spec.tile_width = 641;
  spec.pixel_format = PixelFormat::kNv12;
  EXPECT_EQ(spec.Validate().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(spec.Validate().message().find("pixel_format"), std::string::npos) << spec.Validate().ToString();
}

TEST(SimSensorTest, SameSeedSameBytesOtherSeedOtherNoise) {
  const Scene scene = StillLife();
  SimCameraSpec spec = SmallPop9();
  spec.noise_sigma = 2.0;
  spec.exposure_spread = 0.1;
  spec.vignetting = 0.2;
  auto a = RenderSensorFrame(scene, spec, 5);
  auto b = RenderSensorFrame(scene, spec, 5);
  auto c = RenderSensorFrame(scene, spec, 6);
  ASSERT_TRUE(a.ok() && b.ok() && c.ok());
  EXPECT_EQ(a->sensor.bytes, b->sensor.bytes);
  EXPECT_EQ(a->truth.exposure_gains, b->truth.exposure_gains);
  EXPECT_NE(a->sensor.bytes, c->sensor.bytes);
  EXPECT_NE(a->truth.exposure_gains, c->truth.exposure_gains);
  // Only the sensor effects depend on the seed: the clean ground truth does not.
  for (size_t i = 0; i < a->truth.views.size(); ++i) {
    EXPECT_EQ(cv::norm(a->truth.views[i].bgr, c->truth.views[i].bgr, cv::NORM_INF), 0.0);
  }
  // The difference between seeds is noise of the configured size: sigma * sqrt(2) per pixel
  // for equal gains; here gains differ too, so only check it is clearly non-zero.
  const cv::Mat da = Decode(a->sensor), dc = Decode(c->sensor);
  cv::Mat diff;
  cv::absdiff(da, dc, diff);
  EXPECT_GT(cv::mean(diff)[0], 1.0);
}

TEST(SimSensorTest, TilesSitInTheLayoutTurnedBy180WithDarkGapsBetween) {
  const Scene scene = StillLife();
  const SimCameraSpec spec = SmallPop9();  // no noise, vignetting or gain spread
  auto frame = RenderSensorFrame(scene, spec, 1);
  ASSERT_TRUE(frame.ok()) << frame.status().ToString();
  const cv::Mat sensor = Decode(frame->sensor);
  const LatticeLayout layout = spec.Layout();
  ASSERT_EQ(sensor.cols, layout.sensor_width);
  ASSERT_EQ(sensor.rows, layout.sensor_height);
  cv::Mat in_tiles(sensor.size(), CV_8U, cv::Scalar(0));
  for (int i = 0; i < layout.NumViews(); ++i) {
    const cv::Rect rect = layout.tiles[i].rect;
    EXPECT_EQ(rect,
              cv::Rect(spec.gap_px + layout.tiles[i].col * (spec.tile_width + spec.gap_px),
                       spec.gap_px + layout.tiles[i].row * (spec.tile_height + spec.gap_px),
                       spec.tile_width,
                       spec.tile_height));
    in_tiles(rect).setTo(255);
    const cv::Mat& upright = frame->truth.views[i].bgr;
    // Stored pixel (x, y) of the tile is upright pixel (w-1-x, h-1-y): rotated by 180 degrees.
    int mismatches = 0;
    for (int y = 0; y < rect.height; ++y) {
      for (int x = 0; x < rect.width; ++x) {
        mismatches += sensor.at<cv::Vec3b>(rect.y + y, rect.x + x) !=
                      upright.at<cv::Vec3b>(rect.height - 1 - y, rect.width - 1 - x);
      }
    }
    EXPECT_EQ(mismatches, 0) << "tile " << i;
  }
  // Everything outside the tiles is the dark level with slight noise.
  cv::Scalar mean, stddev;
  cv::meanStdDev(sensor, mean, stddev, ~in_tiles);
  for (int ch = 0; ch < 3; ++ch) {
    EXPECT_NEAR(mean[ch], spec.gap_level, 0.2);
    EXPECT_NEAR(stddev[ch], spec.gap_noise_sigma, 0.2);
  }
}

TEST(SimSensorTest, OtherOrientationsAreHonoured) {
  const Scene scene = StillLife();
  for (TileOrientation orientation : {TileOrientation::kUpright, TileOrientation::kMirroredX}) {
    SimCameraSpec spec = SmallPop9();
    spec.orientation = orientation;
    auto frame = RenderSensorFrame(scene, spec, 1);
    ASSERT_TRUE(frame.ok());
    const cv::Mat sensor = Decode(frame->sensor);
    const cv::Rect rect = spec.Layout().tiles[4].rect;
    const cv::Mat& upright = frame->truth.views[4].bgr;
    const int x = 10, y = 20;
    const int stored_x = orientation == TileOrientation::kUpright ? x : rect.width - 1 - x;
    EXPECT_EQ(sensor.at<cv::Vec3b>(rect.y + y, rect.x + stored_x), upright.at<cv::Vec3b>(y, x))
        << TileOrientationName(orientation);
  }
}

TEST(SimSensorTest, EveryPixelFormatDecodesCloseToTheCleanRender) {
  const Scene scene = StillLife();
  // Tolerances are mean absolute errors over all tile pixels, from what each format throws
  // away: RGB888 nothing; YUYV half-resolution chroma plus limited-range quantisation; NV12
  // quarter-resolution chroma; SRGGB8 two of three colours per pixel, demosaiced (worst at
  // texture edges). Measured on this scene: 0, 1.1, 1.5 and 2.4 levels.
  const std::vector<std::pair<PixelFormat, double>> formats = {{PixelFormat::kRgb888, 0.0},
                                                               {PixelFormat::kYuyv, 2.0},
                                                               {PixelFormat::kNv12, 2.5},
                                                               {PixelFormat::kBayerRggb8, 4.0}};
  for (const auto& [format, tolerance] : formats) {
    SimCameraSpec spec = Quartered(SimCameraSpec::Pop9());
    spec.supersampling = 1;
    spec.pixel_format = format;
    auto frame = RenderSensorFrame(scene, spec, 1);
    ASSERT_TRUE(frame.ok()) << frame.status().ToString();
    EXPECT_EQ(frame->sensor.format, format);
    EXPECT_TRUE(frame->sensor.Validate().ok());
    const cv::Mat sensor = Decode(frame->sensor);
    const LatticeLayout layout = spec.Layout();
    double total = 0;
    for (int i = 0; i < layout.NumViews(); ++i) {
      const cv::Mat upright = OrientTile(sensor(layout.tiles[i].rect), layout.tiles[i].orientation);
      cv::Mat diff;
      cv::absdiff(upright, frame->truth.views[i].bgr, diff);
      const cv::Scalar m = cv::mean(diff);
      total += (m[0] + m[1] + m[2]) / 3;
    }
    const double mean_error = total / layout.NumViews();
    EXPECT_LE(mean_error, tolerance) << PixelFormatName(format);
    RecordProperty(std::string(PixelFormatName(format)) + "_mean_abs_error", std::to_string(mean_error));
  }
}

TEST(SimSensorTest, VignettingExposureAndNoiseHaveTheConfiguredSize) {
  const Scene scene = FlatWall();
  SimCameraSpec spec = SmallPop9();
  spec.vignetting = 0.3;
  spec.exposure_spread = 0.1;
  spec.noise_sigma = 3.0;
  spec.gap_noise_sigma = 0.0;
  auto frame = RenderSensorFrame(scene, spec, 9);
  ASSERT_TRUE(frame.ok());
  const cv::Mat sensor = Decode(frame->sensor);
  const LatticeLayout layout = spec.Layout();
  const std::vector<double>& gains = frame->truth.exposure_gains;
  ASSERT_EQ(gains.size(), 9u);
  for (double g : gains) {
    EXPECT_GE(g, 0.9);
    EXPECT_LE(g, 1.1);
  }
  EXPECT_GT(*std::max_element(gains.begin(), gains.end()) - *std::min_element(gains.begin(), gains.end()), 0.02);
  for (int i = 0; i < layout.NumViews(); ++i) {
    const cv::Mat upright = OrientTile(sensor(layout.tiles[i].rect), layout.tiles[i].orientation);
    cv::Mat value;
    upright.convertTo(value, CV_32FC3);
    // Expected: 200 * gain * (1 - 0.3 (r / r_corner)^2); the residual is the noise.
    const CameraModel& camera = frame->truth.views[i].camera;
    const double r2_corner = camera.cx * camera.cx + camera.cy * camera.cy;
    double sum = 0, sum2 = 0;
    int n = 0;
    for (int y = 0; y < value.rows; ++y) {
      for (int x = 0; x < value.cols; ++x) {
        const double r2 = (x - camera.cx) * (x - camera.cx) + (y - camera.cy) * (y - camera.cy);
        const double expected = 200.0 * gains[i] * (1.0 - 0.3 * r2 / r2_corner);
        const double residual = value.at<cv::Vec3f>(y, x)[1] - expected;
        sum += residual;
        sum2 += residual * residual;
        ++n;
      }
    }
    const double mean = sum / n, sigma = std::sqrt(sum2 / n - mean * mean);
    // 19200 samples: the mean of N(0, 3) is known to +-0.07 (3 sigma); rounding to integers
    // adds 1/12 variance, so sigma is sqrt(9 + 0.083) = 3.01 +- 0.05.
    EXPECT_NEAR(mean, 0.0, 0.1) << "tile " << i;
    EXPECT_NEAR(sigma, 3.0, 0.1) << "tile " << i;
  }
}

}  // namespace
}  // namespace px::sim
