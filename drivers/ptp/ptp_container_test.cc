// PTP containers, strings, arrays and datasets: round trips, exact bytes, and garbled input
// that must fail with an error naming the field (never a crash or an over-read).
#include "drivers/ptp/ptp_container.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>

#include "drivers/ptp/ptp_bytes.h"
#include "drivers/ptp/ptp_datasets.h"

namespace px::ptp {
namespace {

using ::testing::HasSubstr;

DeviceInfo SampleDeviceInfo() {
  DeviceInfo info;
  info.vendor_extension_id = 6;
  info.vendor_extension_version = 100;
  info.vendor_extension_desc = "microsoft.com: 1.0";
  info.operations_supported = {op::kGetDeviceInfo, op::kOpenSession, op::kInitiateCapture, op::kGetObject};
  info.events_supported = {ev::kObjectAdded, ev::kCaptureComplete};
  info.device_properties_supported = {prop::kImageSize};
  info.capture_formats = {fmt::kExifJpeg};
  info.image_formats = {fmt::kExifJpeg, fmt::kAssociation};
  info.manufacturer = "Canon Inc.";
  info.model = "Canon EOS 5D";
  info.device_version = "3-1.1.0";
  info.serial_number = "0123456789";
  return info;
}

ObjectInfo SampleObjectInfo() {
  ObjectInfo info;
  info.storage_id = 0x00010001;
  info.object_format = fmt::kExifJpeg;
  info.object_compressed_size = 4123456;
  info.image_pix_width = 6000;
  info.image_pix_height = 4000;
  info.image_bit_depth = 24;
  info.parent_object = 0x20;
  info.sequence_number = 7;
  info.filename = "IMG_0007.JPG";
  info.capture_date = "20260101T120000.0";
  return info;
}

TEST(PtpContainer, CommandEncodesToTheExactBytes) {
  Container command{ContainerType::kCommand, op::kGetObject, 0x01020304, {0xAABBCCDD}, {}};
  auto bytes = EncodeContainer(command);
  ASSERT_TRUE(bytes.ok()) << bytes.status().ToString();
  const std::vector<uint8_t> want = {
      0x10, 0, 0, 0, 0x01, 0x00, 0x09, 0x10, 0x04, 0x03, 0x02, 0x01, 0xDD, 0xCC, 0xBB, 0xAA};
  EXPECT_EQ(*bytes, want);
}

TEST(PtpContainer, EveryKindRoundTrips) {
  const std::vector<Container> containers = {
      {ContainerType::kCommand, op::kOpenSession, 0, {1}, {}},
      {ContainerType::kCommand, op::kInitiateCapture, 5, {0, 0, 3, 4, 5}, {}},
      {ContainerType::kData, op::kGetObject, 9, {}, std::vector<uint8_t>(1000, 0x5A)},
      {ContainerType::kData, op::kGetObject, 9, {}, {}},
      {ContainerType::kResponse, rc::kOk, 9, {}, {}},
      {ContainerType::kResponse, rc::kDeviceBusy, 10, {7, 8}, {}},
      {ContainerType::kEvent, ev::kObjectAdded, 11, {0x10001}, {}},
      {ContainerType::kEvent, ev::kCaptureComplete, 11, {11, 2, 3}, {}},
  };
  for (const Container& c : containers) {
    auto bytes = EncodeContainer(c);
    ASSERT_TRUE(bytes.ok()) << bytes.status().ToString();
    auto back = DecodeContainer(*bytes, "test");
    ASSERT_TRUE(back.ok()) << back.status().ToString();
    EXPECT_EQ(*back, c) << ContainerTypeName(c.type) << " " << c.code;
  }
}

TEST(PtpContainer, EncodingRefusesImpossibleContainers) {
  EXPECT_FALSE(EncodeContainer({ContainerType::kCommand, 1, 0, {1, 2, 3, 4, 5, 6}, {}}).ok());
  EXPECT_FALSE(EncodeContainer({ContainerType::kEvent, 1, 0, {1, 2, 3, 4}, {}}).ok());
  EXPECT_FALSE(EncodeContainer({ContainerType::kData, 1, 0, {1}, {}}).ok());
  EXPECT_FALSE(EncodeContainer({ContainerType::kResponse, 1, 0, {}, {1, 2}}).ok());
}

TEST(PtpContainer, GarbledContainersNameTheField) {
  auto good = EncodeContainer({ContainerType::kResponse, rc::kOk, 3, {1, 2}, {}});
  ASSERT_TRUE(good.ok());

  std::vector<uint8_t> short_header(good->begin(), good->begin() + 7);
  auto a = DecodeContainer(short_header, "response to X");
  ASSERT_FALSE(a.ok());
  EXPECT_EQ(a.status().code(), StatusCode::kDataLoss);
  EXPECT_THAT(a.status().message(), HasSubstr("code"));
  EXPECT_THAT(a.status().message(), HasSubstr("response to X"));

  std::vector<uint8_t> wrong_length = *good;
  wrong_length[0] = 0x40;
  auto b = DecodeContainer(wrong_length, "r");
  ASSERT_FALSE(b.ok());
  EXPECT_THAT(b.status().message(), HasSubstr("field length: says 64 bytes, got 20"));

  std::vector<uint8_t> tiny_length = *good;
  tiny_length[0] = 4;
  auto c = DecodeContainer(tiny_length, "r");
  ASSERT_FALSE(c.ok());
  EXPECT_THAT(c.status().message(), HasSubstr("shorter than the 12-byte header"));

  std::vector<uint8_t> bad_type = *good;
  bad_type[4] = 9;
  auto d = DecodeContainer(bad_type, "r");
  ASSERT_FALSE(d.ok());
  EXPECT_THAT(d.status().message(), HasSubstr("field type: 9"));

  std::vector<uint8_t> ragged = *good;
  ragged.push_back(0);
  ragged[0] = static_cast<uint8_t>(ragged.size());
  auto e = DecodeContainer(ragged, "r");
  ASSERT_FALSE(e.ok());
  EXPECT_THAT(e.status().message(), HasSubstr("field params"));

  auto too_many = EncodeContainer({ContainerType::kResponse, rc::kOk, 3, {1, 2, 3, 4, 5}, {}});
  ASSERT_TRUE(too_many.ok());
  too_many->insert(too_many->end(), {0, 0, 0, 0});
  (*too_many)[0] = static_cast<uint8_t>(too_many->size());
  EXPECT_FALSE(DecodeContainer(*too_many, "r").ok());
}

TEST(PtpBytes, StringsAndArraysRoundTripAndFailCleanly) {
  ByteWriter out;
  out.String("IMG_0001.JPG");
  out.String("");
  out.U16Array({1, 2, 0xFFFF});
  out.U32Array({});
  ByteReader in(out.bytes(), "test");
  EXPECT_EQ(*in.String("a"), "IMG_0001.JPG");
  EXPECT_EQ(*in.String("b"), "");
  EXPECT_EQ(*in.U16Array("c"), (std::vector<uint16_t>{1, 2, 0xFFFF}));
  EXPECT_TRUE(in.U32Array("d")->empty());
  EXPECT_EQ(in.remaining(), 0u);

  // A string without its NUL.
  std::vector<uint8_t> no_nul = {2, 'A', 0, 'B', 0};
  ByteReader r1(no_nul, "Obj");
  auto s = r1.String("Filename");
  ASSERT_FALSE(s.ok());
  EXPECT_THAT(s.status().message(), HasSubstr("Filename"));
  EXPECT_THAT(s.status().message(), HasSubstr("NUL"));

  // An array whose count runs past the end must not allocate or read it.
  std::vector<uint8_t> huge = {0xFF, 0xFF, 0xFF, 0x7F, 1, 0};
  ByteReader r2(huge, "DeviceInfo");
  auto array = r2.U16Array("OperationsSupported");
  ASSERT_FALSE(array.ok());
  EXPECT_THAT(array.status().message(), HasSubstr("OperationsSupported"));
  EXPECT_THAT(array.status().message(), HasSubstr("2147483647 x UINT16"));
}

TEST(PtpDatasets, DeviceInfoAndObjectInfoRoundTrip) {
  const DeviceInfo device = SampleDeviceInfo();
  auto device_back = DecodeDeviceInfo(EncodeDeviceInfo(device));
  ASSERT_TRUE(device_back.ok()) << device_back.status().ToString();
  EXPECT_EQ(*device_back, device);
  EXPECT_TRUE(device_back->SupportsOperation(op::kInitiateCapture));
  EXPECT_FALSE(device_back->SupportsOperation(op::kDeleteObject));
  EXPECT_TRUE(device_back->SupportsProperty(prop::kImageSize));

  const ObjectInfo object = SampleObjectInfo();
  auto object_back = DecodeObjectInfo(EncodeObjectInfo(object));
  ASSERT_TRUE(object_back.ok()) << object_back.status().ToString();
  EXPECT_EQ(*object_back, object);
}

TEST(PtpDatasets, EveryTruncationIsAnErrorNamingAField) {
  const std::vector<uint8_t> device = EncodeDeviceInfo(SampleDeviceInfo());
  for (size_t n = 0; n < device.size(); ++n) {
    auto info = DecodeDeviceInfo(std::span(device.data(), n));
    ASSERT_FALSE(info.ok()) << "DeviceInfo cut at " << n;
    EXPECT_EQ(info.status().code(), StatusCode::kDataLoss);
    EXPECT_THAT(info.status().message(), HasSubstr("DeviceInfo: field "));
  }
  const std::vector<uint8_t> object = EncodeObjectInfo(SampleObjectInfo());
  for (size_t n = 0; n < object.size(); ++n) {
    auto info = DecodeObjectInfo(std::span(object.data(), n));
    ASSERT_FALSE(info.ok()) << "ObjectInfo cut at " << n;
    EXPECT_THAT(info.status().message(), HasSubstr("ObjectInfo: field "));
  }
  // The field named is the one that was cut: Model's string starts after Manufacturer's.
  ByteWriter prefix;
  prefix.U16(100);
  prefix.U32(0);
  prefix.U16(0);
  prefix.String("");
  prefix.U16(0);
  for (int i = 0; i < 5; ++i) prefix.U16Array({});
  prefix.String("Canon Inc.");
  prefix.U8(40);  // Model claims 40 characters, none follow
  auto cut = DecodeDeviceInfo(prefix.bytes());
  ASSERT_FALSE(cut.ok());
  EXPECT_THAT(cut.status().message(), HasSubstr("field Model"));
}

TEST(PtpDatasets, RandomBytesNeverCrash) {
  std::mt19937 rng(7);
  std::vector<uint8_t> base = EncodeDeviceInfo(SampleDeviceInfo());
  int decoded = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    std::vector<uint8_t> bytes = base;
    const int flips = 1 + static_cast<int>(rng() % 4);
    for (int f = 0; f < flips; ++f) bytes[rng() % bytes.size()] = static_cast<uint8_t>(rng());
    bytes.resize(rng() % (bytes.size() + 1));
    decoded += DecodeDeviceInfo(bytes).ok();
    decoded += DecodeObjectInfo(bytes).ok();
    decoded += DecodeContainer(bytes, "fuzz").ok();
  }
  SUCCEED() << decoded << " garbled inputs still decoded";
}

}  // namespace
}  // namespace px::ptp
