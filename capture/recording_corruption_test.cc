// Bad recordings: each must be refused with an error that names the file and the field, and
// never crash. Frames whose manifest status is not ok are loaded as they are.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "capture/recording.h"
#include "capture/recording_test_util.h"
#include "capture/sha256.h"

namespace px {
namespace {

namespace fs = std::filesystem;
using capture::testing::ReadText;
using capture::testing::WriteText;
using ::testing::AllOf;
using ::testing::HasSubstr;

class CorruptionTest : public ::testing::Test {
 protected:
  // A PNG recording (BGR888) with rig and a raw one (YUYV) without.
  void SetUp() override {
    ASSERT_TRUE(WriteRecording(png_dir_, capture::testing::LatticeRecording(PixelFormat::kBgr888)).ok());
    Recording raw = capture::testing::LatticeRecording(PixelFormat::kYuyv);
    raw.source.rig.reset();
    ASSERT_TRUE(WriteRecording(raw_dir_, raw).ok());
  }

  static nlohmann::json Manifest(const fs::path& dir) { return nlohmann::json::parse(ReadText(dir / "manifest.json")); }
  static void SetManifest(const fs::path& dir, const nlohmann::json& j) { WriteText(dir / "manifest.json", j.dump(2)); }

  // Makes the manifest agree with the frame file again (size and checksum), so that the check
  // behind the checksum is the one that has to catch the damage.
  static void ResealFrame(const fs::path& dir, const std::string& file) {
    const std::string bytes = ReadText(dir / file);
    nlohmann::json j = Manifest(dir);
    j["frames"][0]["bytes"] = bytes.size();
    j["frames"][0]["sha256"] = capture::Sha256Hex(std::vector<uint8_t>(bytes.begin(), bytes.end()));
    SetManifest(dir, j);
  }

  static Status Read(const fs::path& dir) {
    StatusOr<Recording> recording = ReadRecording(dir);
    return recording.status();
  }

  capture::testing::ScratchDir scratch_;
  const fs::path png_dir_ = scratch_.path() / "png";
  const fs::path raw_dir_ = scratch_.path() / "raw";
  const std::string png_manifest_ = (png_dir_ / "manifest.json").string();
  const std::string raw_manifest_ = (raw_dir_ / "manifest.json").string();
};

TEST_F(CorruptionTest, MissingManifest) {
  fs::remove(png_dir_ / "manifest.json");
  Status status = Read(png_dir_);
  EXPECT_EQ(status.code(), StatusCode::kNotFound);
  EXPECT_THAT(status.message(), HasSubstr(png_manifest_ + ": missing"));
  EXPECT_EQ(Read(scratch_.path() / "nowhere").code(), StatusCode::kNotFound);
}

TEST_F(CorruptionTest, MissingFrameFile) {
  fs::remove(png_dir_ / "frame_0000.png");
  Status status = Read(png_dir_);
  EXPECT_EQ(status.code(), StatusCode::kDataLoss);
  EXPECT_THAT(status.message(),
              AllOf(HasSubstr((png_dir_ / "frame_0000.png").string() + ": missing"), HasSubstr("frames[0].file")));
}

TEST_F(CorruptionTest, TruncatedPng) {
  const std::string png = ReadText(png_dir_ / "frame_0000.png");
  WriteText(png_dir_ / "frame_0000.png", png.substr(0, png.size() / 2));
  Status status = Read(png_dir_);
  EXPECT_EQ(status.code(), StatusCode::kDataLoss);
  EXPECT_THAT(status.message(),
              AllOf(HasSubstr((png_dir_ / "frame_0000.png").string() + ": truncated"),
                    HasSubstr("frames[0].bytes says " + std::to_string(png.size()))));

  // Even when the manifest was written for the truncated file, the decoder catches it.
  ResealFrame(png_dir_, "frame_0000.png");
  status = Read(png_dir_);
  EXPECT_EQ(status.code(), StatusCode::kDataLoss);
  EXPECT_THAT(
      status.message(),
      AllOf(HasSubstr((png_dir_ / "frame_0000.png").string() + ": truncated or not a PNG"), HasSubstr("frames[0]")));
}

TEST_F(CorruptionTest, GarbledPngBytes) {
  std::string png = ReadText(png_dir_ / "frame_0000.png");
  for (size_t i = png.size() / 3; i < png.size() / 3 + 16; ++i) png[i] = static_cast<char>(png[i] ^ 0x5a);
  WriteText(png_dir_ / "frame_0000.png", png);
  Status status = Read(png_dir_);
  EXPECT_EQ(status.code(), StatusCode::kDataLoss);
  EXPECT_THAT(status.message(),
              AllOf(HasSubstr((png_dir_ / "frame_0000.png").string() + ": garbled"), HasSubstr("frames[0].sha256")));

  // Behind a matching checksum, libpng's chunk CRC or zlib still refuses the data.
  ResealFrame(png_dir_, "frame_0000.png");
  status = Read(png_dir_);
  EXPECT_EQ(status.code(), StatusCode::kDataLoss);
  EXPECT_THAT(status.message(), HasSubstr((png_dir_ / "frame_0000.png").string() + ": truncated or not a PNG"));

  // Not a PNG at all.
  WriteText(png_dir_ / "frame_0000.png", "GIF89a this is not what the manifest promised");
  ResealFrame(png_dir_, "frame_0000.png");
  EXPECT_THAT(Read(png_dir_).message(), HasSubstr("no PNG signature"));
}

TEST_F(CorruptionTest, RawFileOfTheWrongLength) {
  const std::string raw = ReadText(raw_dir_ / "frame_0000.raw");
  WriteText(raw_dir_ / "frame_0000.raw", raw + "xyz");
  Status status = Read(raw_dir_);
  EXPECT_EQ(status.code(), StatusCode::kDataLoss);
  EXPECT_THAT(status.message(),
              AllOf(HasSubstr((raw_dir_ / "frame_0000.raw").string()),
                    HasSubstr("has " + std::to_string(raw.size() + 3) + " bytes"),
                    HasSubstr("frames[0].bytes says " + std::to_string(raw.size()))));

  // A manifest that agrees with the long file still contradicts the frame's size and format.
  ResealFrame(raw_dir_, "frame_0000.raw");
  status = Read(raw_dir_);
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(),
              AllOf(HasSubstr(raw_manifest_),
                    HasSubstr("frames[0].bytes: " + std::to_string(raw.size() + 3)),
                    HasSubstr("136x106 YUYV frame has " + std::to_string(raw.size()))));
}

TEST_F(CorruptionTest, WrongDimensionsInTheManifest) {
  // Without a rig, the PNG's own size contradicts the manifest.
  Recording no_rig = capture::testing::LatticeRecording(PixelFormat::kBgr888);
  no_rig.source.rig.reset();
  const fs::path dir = scratch_.path() / "no_rig";
  ASSERT_TRUE(WriteRecording(dir, no_rig).ok());
  nlohmann::json j = Manifest(dir);
  j["frames"][0]["width"] = 138;
  SetManifest(dir, j);
  Status status = Read(dir);
  EXPECT_EQ(status.code(), StatusCode::kDataLoss);
  EXPECT_THAT(status.message(),
              AllOf(HasSubstr((dir / "frame_0000.png").string()),
                    HasSubstr("decodes to 136x106, the manifest says 138x106"),
                    HasSubstr("frames[0]")));

  // A raw frame: the byte count no longer fits the size.
  j = Manifest(raw_dir_);
  j["frames"][0]["height"] = 100;
  SetManifest(raw_dir_, j);
  EXPECT_THAT(Read(raw_dir_).message(), AllOf(HasSubstr(raw_manifest_), HasSubstr("frames[0].bytes")));
}

TEST_F(CorruptionTest, LatticeInconsistentWithTheFrameSize) {
  nlohmann::json j = Manifest(png_dir_);
  j["source"]["rig_calibration"]["lattice"]["sensor_width"] = 200;  // tiles still fit, the frame does not
  SetManifest(png_dir_, j);
  Status status = Read(png_dir_);
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(),
              AllOf(HasSubstr(png_manifest_),
                    HasSubstr("frames[0].width, height: 136x106 differs"),
                    HasSubstr("source.rig_calibration.lattice.sensor_width")));

  j["source"]["rig_calibration"]["lattice"]["sensor_width"] = 100;  // a tile now leaves the sensor
  SetManifest(png_dir_, j);
  EXPECT_THAT(
      Read(png_dir_).message(),
      AllOf(HasSubstr(png_manifest_), HasSubstr("source.rig_calibration"), HasSubstr("leaves the 100x106 sensor")));
}

TEST_F(CorruptionTest, UnknownPixelFormat) {
  nlohmann::json j = Manifest(png_dir_);
  j["frames"][0]["pixel_format"] = "MJPG";
  SetManifest(png_dir_, j);
  Status status = Read(png_dir_);
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(status.message(),
            png_manifest_ +
                ": frames[0].pixel_format: 'MJPG' is not one of RGB888, BGR888, GRAY8, YUYV, "
                "NV12, SRGGB8");
}

TEST_F(CorruptionTest, MalformedJson) {
  const std::string text = ReadText(png_dir_ / "manifest.json");
  WriteText(png_dir_ / "manifest.json", text.substr(0, 100));
  Status status = Read(png_dir_);
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(), AllOf(HasSubstr(png_manifest_), HasSubstr("malformed JSON at byte 101")));

  WriteText(png_dir_ / "manifest.json", "{\"format\": \"parallax.recording\",, }");
  EXPECT_THAT(Read(png_dir_).message(), HasSubstr("malformed JSON at byte 33"));

  WriteText(png_dir_ / "manifest.json", "[1, 2]");
  EXPECT_THAT(Read(png_dir_).message(), HasSubstr(png_manifest_ + ": document: want an object, got array"));
}

TEST_F(CorruptionTest, MissingOrMistypedFields) {
  struct Case {
    std::function<void(nlohmann::json&)> damage;
    std::string message;
  };
  const std::vector<Case> cases = {
      {[](auto& j) { j["frames"][0].erase("sequence"); }, "frames[0].sequence: missing"},
      {[](auto& j) { j.erase("source"); }, "source: missing"},
      {[](auto& j) { j["source"].erase("kind"); }, "source.kind: missing"},
      {[](auto& j) { j.erase("frames"); }, "frames: missing"},
      {[](auto& j) { j.erase("created_at"); }, "created_at: missing"},
      {[](auto& j) { j["frames"][0]["width"] = "136"; }, "frames[0].width: want an integer, got string"},
      {[](auto& j) { j["frames"][0]["timestamp_ns"] = 1.5; }, "frames[0].timestamp_ns: want an integer, got number"},
      {[](auto& j) { j["capture_id"] = -1; }, "capture_id: -1 is negative"},
      {[](auto& j) { j["frames"] = nlohmann::json::object(); }, "frames: want an array, got object"},
      {[](auto& j) { j["frames"] = nlohmann::json::array(); }, "frames: empty"},
      {[](auto& j) { j["frames"][0]["status"] = "fine"; }, "frames[0].status: frame status 'fine' is not one of"},
      {[](auto& j) { j["frames"][0]["sha256"] = "abc"; }, "frames[0].sha256: 'abc' is not 64 lowercase hex digits"},
      {[](auto& j) { j["frames"][0]["file"] = "../../etc/passwd"; },
       "frames[0].file: '../../etc/passwd' is not a plain"},
      {[](auto& j) { j["frames"][0]["file"] = nullptr; },
       "frames[0].file: a frame has both a file and its sha256, or neither"},
      {[](auto& j) { j["source"]["rig_calibration"]["lenses"][3]["camera"].erase("fx"); },
       "source.rig_calibration.lenses[3].camera.fx: missing"},
      {[](auto& j) { j["created_at"] = "yesterday"; }, "created_at: 'yesterday' is not UTC ISO 8601"},
      {[](auto& j) { j["format"] = "parallax.video"; }, "format: 'parallax.video' is not parallax.recording"},
  };
  const nlohmann::json original = Manifest(png_dir_);
  for (const Case& c : cases) {
    nlohmann::json j = original;
    c.damage(j);
    SetManifest(png_dir_, j);
    Status status = Read(png_dir_);
    EXPECT_EQ(status.code(), StatusCode::kInvalidArgument) << status.ToString();
    EXPECT_THAT(status.message(), HasSubstr(png_manifest_ + ": " + c.message));
  }
}

TEST_F(CorruptionTest, UnsupportedVersion) {
  nlohmann::json j = Manifest(png_dir_);
  j["format_version"] = 2;
  SetManifest(png_dir_, j);
  Status status = Read(png_dir_);
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(status.message(), png_manifest_ + ": format_version: 2 is not a supported version (this build reads 1)");
}

TEST_F(CorruptionTest, OkFrameWithoutAFileIsRefusedButADroppedOneIsLoaded) {
  nlohmann::json j = Manifest(png_dir_);
  j["frames"][0]["file"] = nullptr;
  j["frames"][0]["sha256"] = nullptr;
  j["frames"][0]["bytes"] = 0;
  SetManifest(png_dir_, j);
  EXPECT_THAT(Read(png_dir_).message(), HasSubstr("frames[0].file: null, but status ok promises a frame file"));

  j["frames"][0]["status"] = "dropped";
  SetManifest(png_dir_, j);
  StatusOr<Recording> recording = ReadRecording(png_dir_);
  ASSERT_TRUE(recording.ok()) << recording.status().ToString();
  EXPECT_EQ(recording->frames.frames[0].status, FrameStatus::kDropped);
  EXPECT_TRUE(recording->frames.frames[0].image.bytes.empty());
}

TEST_F(CorruptionTest, ACorruptFrameIsLoadedAsRecordedButOnlyIfItsFileIsIntact) {
  Recording recording = capture::testing::LatticeRecording(PixelFormat::kBayerRggb8);
  Frame& frame = recording.frames.frames[0];
  frame.image.bytes.resize(frame.image.bytes.size() - 1000);
  frame.status = FrameStatus::kCorrupt;
  frame.status_detail = "short DMA transfer";
  const fs::path dir = scratch_.path() / "corrupt";
  ASSERT_TRUE(WriteRecording(dir, recording).ok());
  StatusOr<Recording> back = ReadRecording(dir);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  capture::testing::ExpectSameRecording(recording, *back);

  // The capture was bad, but the recording of it must still be intact.
  std::string raw = ReadText(dir / "frame_0000.raw");
  raw[10] = static_cast<char>(raw[10] ^ 1);
  WriteText(dir / "frame_0000.raw", raw);
  EXPECT_THAT(Read(dir).message(),
              AllOf(HasSubstr((dir / "frame_0000.raw").string() + ": garbled"), HasSubstr("frames[0].sha256")));
}

}  // namespace
}  // namespace px
