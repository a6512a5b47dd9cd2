#include "capture/recording_test_util.h"

#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <system_error>

#include "pipeline/core/rig_calibration_json.h"

namespace px::capture::testing {

cv::Mat GradientNoiseBgr(int width, int height, uint64_t seed) {
  cv::Mat bgr(height, width, CV_8UC3);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      bgr.at<cv::Vec3b>(y, x) = cv::Vec3b(static_cast<uint8_t>(255 * x / std::max(1, width - 1)),
                                          static_cast<uint8_t>(255 * y / std::max(1, height - 1)),
                                          static_cast<uint8_t>(255 * (x + y) / std::max(1, width + height - 2)));
    }
  }
  cv::Mat noise(height, width, CV_16SC3);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::UNIFORM, -20, 21);
  cv::Mat noisy;
  bgr.convertTo(noisy, CV_16SC3);
  noisy += noise;
  noisy.convertTo(bgr, CV_8UC3);  // saturates to [0, 255]
  return bgr;
}

RawImage TestImage(PixelFormat format, int width, int height, uint64_t seed) {
  StatusOr<RawImage> raw = FromBgr(GradientNoiseBgr(width, height, seed), format);
  EXPECT_TRUE(raw.ok()) << raw.status().ToString();
  return raw.ok() ? *raw : RawImage{};
}

RigCalibration SmallPop9Rig() {
  RigCalibration rig;
  rig.rig_name = "test-pop9";
  rig.lattice = LatticeLayout::Regular(3, 3, 40, 30, 4, TileOrientation::kRotated180);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      LensCalibration lens;
      lens.camera = CameraModel::Pinhole(40, 30, 37.5 + 0.1 * (3 * r + c));
      lens.camera.distortion = {-0.031 * r, 0.0123, 1e-4 * c, -2e-4, 0.001};
      // Awkward angles and offsets so any loss of precision in the JSON round trip shows.
      lens.cam_from_rig = Rigid3(
          Eigen::Quaterniond(Eigen::AngleAxisd(0.0123 * c - 0.007 * r, Eigen::Vector3d(0.3, 1, 0.1).normalized())),
          {-0.0213 * (c - 1), -0.0197 * (r - 1), 1e-4 / 3});
      rig.lenses.push_back(lens);
    }
  }
  rig.nominal_depth_min_m = 0.45;
  rig.nominal_depth_max_m = 7.25;
  return rig;
}

Recording LatticeRecording(PixelFormat format, uint64_t seed) {
  const RigCalibration rig = SmallPop9Rig();
  Recording recording;
  recording.source.model = "test:pop9";
  recording.source.kind = FrameSetKind::kLatticeFrame;
  recording.source.rig = rig;
  recording.created_by = "recording_test \"quoted\" \xc3\xa9";  // escapes and UTF-8 survive
  recording.created_at = "2025-03-01T12:34:56Z";
  recording.frames.kind = FrameSetKind::kLatticeFrame;
  recording.frames.capture_id = 41;
  Frame frame;
  frame.image = TestImage(format, rig.lattice.sensor_width, rig.lattice.sensor_height, seed);
  frame.sequence = 1000 + seed;
  frame.timestamp_ns = 1'700'000'000'123'456'789 + static_cast<int64_t>(seed);
  recording.frames.frames.push_back(frame);
  return recording;
}

Recording ImageSetRecording(int num_frames, PixelFormat format, uint64_t seed) {
  Recording recording;
  recording.source.model = "test:handheld";
  recording.source.kind = FrameSetKind::kImageSet;
  recording.created_by = "recording_test";
  recording.created_at = "2025-03-01T12:34:56.250Z";
  recording.frames.kind = FrameSetKind::kImageSet;
  recording.frames.capture_id = 7;
  RigCalibration rig;
  rig.rig_name = "test-handheld";
  for (int i = 0; i < num_frames; ++i) {
    Frame frame;
    frame.image = TestImage(format, 64, 48, seed + i);
    frame.sequence = 10 + i;
    frame.timestamp_ns = 5'000'000 + 33'333'333LL * i;
    recording.frames.frames.push_back(frame);
    LensCalibration lens;
    lens.camera = CameraModel::Pinhole(64, 48, 55.5);
    lens.cam_from_rig = Rigid3(Eigen::Quaterniond::Identity(), {0.05 * i, 0, 0});
    rig.lenses.push_back(lens);
  }
  recording.source.rig = rig;
  return recording;
}

void ExpectSameRecording(const Recording& expected, const Recording& actual) {
  EXPECT_EQ(actual.created_by, expected.created_by);
  EXPECT_EQ(actual.created_at, expected.created_at);
  EXPECT_EQ(actual.source.model, expected.source.model);
  EXPECT_EQ(actual.source.kind, expected.source.kind);
  ASSERT_EQ(actual.source.rig.has_value(), expected.source.rig.has_value());
  if (expected.source.rig) {
    // The JSON form covers every field; equal text means equal doubles to the last bit.
    EXPECT_EQ(RigCalibrationToJson(*actual.source.rig).dump(), RigCalibrationToJson(*expected.source.rig).dump());
  }
  EXPECT_EQ(actual.frames.kind, expected.frames.kind);
  EXPECT_EQ(actual.frames.capture_id, expected.frames.capture_id);
  ASSERT_EQ(actual.frames.frames.size(), expected.frames.frames.size());
  for (size_t i = 0; i < expected.frames.frames.size(); ++i) {
    SCOPED_TRACE("frame " + std::to_string(i));
    const Frame& a = actual.frames.frames[i];
    const Frame& e = expected.frames.frames[i];
    EXPECT_EQ(a.image.format, e.image.format);
    EXPECT_EQ(a.image.width, e.image.width);
    EXPECT_EQ(a.image.height, e.image.height);
    EXPECT_TRUE(a.image.bytes == e.image.bytes) << "pixel bytes differ";
    EXPECT_EQ(a.sequence, e.sequence);
    EXPECT_EQ(a.timestamp_ns, e.timestamp_ns);
    EXPECT_EQ(a.status, e.status);
    EXPECT_EQ(a.status_detail, e.status_detail);
  }
}

std::string ReadText(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

void WriteText(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
  EXPECT_TRUE(out.good()) << "writing " << path;
}

}  // namespace px::capture::testing
