#include "drivers/libcamera/libcamera_formats.h"

#include <gtest/gtest.h>
#include <libcamera/formats.h>

namespace px::libcamera_driver {
namespace {

TEST(LibcameraFormats, PackedRgbNamesFollowTheLittleEndianWord) {
  // libcamera's RGB888 is the 24-bit word R:G:B read little-endian: B first in memory.
  EXPECT_EQ(PxFormatFromFourcc(libcamera::formats::RGB888.fourcc()), PixelFormat::kBgr888);
  EXPECT_EQ(PxFormatFromFourcc(libcamera::formats::BGR888.fourcc()), PixelFormat::kRgb888);
  EXPECT_EQ(FourccFromPxFormat(PixelFormat::kRgb888), libcamera::formats::BGR888.fourcc());
  EXPECT_EQ(FourccFromPxFormat(PixelFormat::kBgr888), libcamera::formats::RGB888.fourcc());
}

TEST(LibcameraFormats, EveryPxFormatRoundTrips) {
  for (PixelFormat format : {PixelFormat::kRgb888,
                             PixelFormat::kBgr888,
                             PixelFormat::kGray8,
                             PixelFormat::kYuyv,
                             PixelFormat::kNv12,
                             PixelFormat::kBayerRggb8}) {
    EXPECT_EQ(PxFormatFromFourcc(FourccFromPxFormat(format)), format) << PixelFormatName(format);
  }
}

TEST(LibcameraFormats, MapsTheLibcameraConstants) {
  EXPECT_EQ(PxFormatFromFourcc(libcamera::formats::YUYV.fourcc()), PixelFormat::kYuyv);
  EXPECT_EQ(PxFormatFromFourcc(libcamera::formats::NV12.fourcc()), PixelFormat::kNv12);
  EXPECT_EQ(PxFormatFromFourcc(libcamera::formats::SRGGB8.fourcc()), PixelFormat::kBayerRggb8);
  EXPECT_EQ(PxFormatFromFourcc(libcamera::formats::R8.fourcc()), PixelFormat::kGray8);
  // The names in the table are libcamera's own.
  for (const FormatMapping& mapping : SupportedFormats()) {
    EXPECT_EQ(libcamera::PixelFormat(mapping.fourcc).toString(), mapping.libcamera_name);
  }
}

TEST(LibcameraFormats, UnconvertibleFormatsAreRefused) {
  EXPECT_FALSE(PxFormatFromFourcc(libcamera::formats::MJPEG.fourcc()).has_value());
  EXPECT_FALSE(PxFormatFromFourcc(libcamera::formats::SRGGB10.fourcc()).has_value());
  EXPECT_FALSE(PxFormatFromFourcc(libcamera::formats::NV21.fourcc()).has_value());
  EXPECT_FALSE(PxFormatFromFourcc(libcamera::formats::XRGB8888.fourcc()).has_value());
}

TEST(LibcameraFormats, DescribesCodes) {
  EXPECT_EQ(DescribeFourcc(kFourccRgb888), "RGB888 (RG24)");
  EXPECT_EQ(DescribeFourcc(libcamera::formats::MJPEG.fourcc()), "MJPG");
  EXPECT_EQ(DescribeFourcc(0x01020304u), "0x01020304");
}

}  // namespace
}  // namespace px::libcamera_driver
