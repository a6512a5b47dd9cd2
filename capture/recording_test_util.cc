#include "capture/recording_test_util.h"

#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
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

std::vector<uint8_t> Jpeg(const cv::Mat& bgr) {
  std::vector<uint8_t> bytes;
  EXPECT_TRUE(cv::imencode(".jpg", bgr, bytes, {cv::IMWRITE_JPEG_QUALITY, 95}));
  return bytes;
}

namespace {

void Put32(std::vector<uint8_t>* out, uint32_t value) {  // big endian
  for (int shift = 24; shift >= 0; shift -= 8) out->push_back(static_cast<uint8_t>(value >> shift));
}
void Put16(std::vector<uint8_t>* out, uint16_t value) {
  out->push_back(static_cast<uint8_t>(value >> 8));
  out->push_back(static_cast<uint8_t>(value));
}

}  // namespace

std::vector<uint8_t> MakeMpo(const std::vector<std::vector<uint8_t>>& images) {
  const size_t count = images.size();
  std::vector<uint8_t> tiff = {'M', 'M', 0, 42};
  Put32(&tiff, 8);  // the IFD
  Put16(&tiff, 3);  // three entries
  const uint32_t entries_offset = 8 + 2 + 3 * 12 + 4;
  Put16(&tiff, 0xB000);
  Put16(&tiff, 7);
  Put32(&tiff, 4);
  tiff.insert(tiff.end(), {'0', '1', '0', '0'});
  Put16(&tiff, 0xB001);
  Put16(&tiff, 4);
  Put32(&tiff, 1);
  Put32(&tiff, static_cast<uint32_t>(count));
  Put16(&tiff, 0xB002);
  Put16(&tiff, 7);
  Put32(&tiff, static_cast<uint32_t>(16 * count));
  Put32(&tiff, entries_offset);
  Put32(&tiff, 0);  // no next IFD
  const size_t segment = 2 + 4 + tiff.size() + 16 * count;
  const size_t header_at = 2 + 4 + 4;  // SOI, APP2 marker and length, "MPF\0"
  const size_t first_size = images[0].size() + 4 + 4 + tiff.size() + 16 * count;
  size_t next = first_size;
  for (size_t i = 0; i < count; ++i) {
    Put32(&tiff, i == 0 ? 0x20030000u : 0x00020002u);  // attribute: base view, then other views
    Put32(&tiff, static_cast<uint32_t>(i == 0 ? first_size : images[i].size()));
    Put32(&tiff, i == 0 ? 0u : static_cast<uint32_t>(next - header_at));
    Put32(&tiff, 0);
    if (i > 0) next += images[i].size();
  }
  std::vector<uint8_t> file = {0xFF, 0xD8, 0xFF, 0xE2};
  Put16(&file, static_cast<uint16_t>(segment));
  file.insert(file.end(), {'M', 'P', 'F', 0});
  file.insert(file.end(), tiff.begin(), tiff.end());
  file.insert(file.end(), images[0].begin() + 2, images[0].end());
  for (size_t i = 1; i < count; ++i) file.insert(file.end(), images[i].begin(), images[i].end());
  return file;
}

std::filesystem::path WriteBytes(const std::filesystem::path& path, const std::vector<uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  return path;
}

}  // namespace px::capture::testing
