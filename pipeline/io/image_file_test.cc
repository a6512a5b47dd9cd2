// Photos from outside are not trusted: the size a header claims is checked before decoding, a JPEG
// is decoded reduced when asked, and every failure names the file.
#include "pipeline/io/image_file.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

namespace px {
namespace {

using ::testing::HasSubstr;

uint32_t Crc32(const std::vector<uint8_t>& bytes) {
  uint32_t crc = 0xFFFFFFFFu;
  for (uint8_t byte : bytes) {
    crc ^= byte;
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

void AppendBigEndian(std::vector<uint8_t>* out, uint32_t value) {
  for (int shift = 24; shift >= 0; shift -= 8) out->push_back(static_cast<uint8_t>(value >> shift));
}

void AppendChunk(std::vector<uint8_t>* out, const char* type, const std::vector<uint8_t>& data) {
  AppendBigEndian(out, static_cast<uint32_t>(data.size()));
  std::vector<uint8_t> typed(type, type + 4);
  typed.insert(typed.end(), data.begin(), data.end());
  out->insert(out->end(), typed.begin(), typed.end());
  AppendBigEndian(out, Crc32(typed));
}

// A well-formed PNG header claiming width x height RGB pixels, with a few bytes of image data.
std::vector<uint8_t> CraftedPng(uint32_t width, uint32_t height) {
  std::vector<uint8_t> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  std::vector<uint8_t> header;
  AppendBigEndian(&header, width);
  AppendBigEndian(&header, height);
  header.insert(header.end(), {8, 2, 0, 0, 0});
  AppendChunk(&png, "IHDR", header);
  // A zlib stream of one stored block of 100 zero bytes (Adler-32 of zeros: 100 << 16 | 1).
  std::vector<uint8_t> packed = {0x78, 0x01, 0x01, 100, 0, 155, 255};
  packed.insert(packed.end(), 100, 0);
  AppendBigEndian(&packed, (100u << 16) | 1u);
  AppendChunk(&png, "IDAT", packed);
  AppendChunk(&png, "IEND", {});
  return png;
}

std::vector<uint8_t> Encoded(const cv::Mat& image, const std::string& extension) {
  std::vector<uint8_t> bytes;
  EXPECT_TRUE(cv::imencode(extension, image, bytes));
  return bytes;
}

cv::Mat Gradient(int width, int height) {
  cv::Mat image(height, width, CV_8UC3);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) image.at<cv::Vec3b>(y, x) = cv::Vec3b(x % 256, y % 256, (x + y) % 256);
  }
  return image;
}

TEST(ImageFileTest, HeadersGiveTheSizeWithoutDecoding) {
  const cv::Mat image = Gradient(300, 200);
  for (const char* extension : {".jpg", ".png", ".webp"}) {
    auto size = ReadImageHeaderSize(Encoded(image, extension));
    ASSERT_TRUE(size.ok()) << extension << ": " << size.status().ToString();
    EXPECT_EQ(size->width, 300) << extension;
    EXPECT_EQ(size->height, 200) << extension;
  }
  auto crafted = ReadImageHeaderSize(CraftedPng(40000, 40000));
  ASSERT_TRUE(crafted.ok());
  EXPECT_EQ(crafted->width, 40000);
}

TEST(ImageFileTest, AHeaderClaimingTooManyPixelsIsRefusedBeforeDecoding) {
  auto decoded = DecodeImageBytes(CraftedPng(40000, 40000), "crafted.png");
  ASSERT_FALSE(decoded.ok());
  EXPECT_EQ(decoded.status().code(), StatusCode::kResourceExhausted);
  EXPECT_THAT(decoded.status().message(), HasSubstr("crafted.png: its header claims 40000x40000 pixels (1600 MP)"));
  // Under the limit the same lie is only a damaged file.
  auto small_lie = DecodeImageBytes(CraftedPng(4000, 3000), "lie.png");
  ASSERT_FALSE(small_lie.ok());
  EXPECT_EQ(small_lie.status().code(), StatusCode::kDataLoss);
  EXPECT_THAT(small_lie.status().message(), HasSubstr("lie.png: cannot be decoded"));
}

TEST(ImageFileTest, GarbageAndTruncatedFilesAreClearErrors) {
  const std::vector<uint8_t> garbage = {'h', 'e', 'l', 'l', 'o', ' ', 'w', 'o', 'r', 'l', 'd'};
  auto not_image = DecodeImageBytes(garbage, "notes.jpg");
  ASSERT_FALSE(not_image.ok());
  EXPECT_THAT(not_image.status().message(), HasSubstr("notes.jpg: cannot be decoded: not a JPEG, PNG, GIF or WebP"));
  std::vector<uint8_t> jpeg = Encoded(Gradient(300, 200), ".jpg");
  jpeg.resize(40);  // cut before its frame header
  auto truncated = DecodeImageBytes(jpeg, "cut.jpg");
  ASSERT_FALSE(truncated.ok());
  EXPECT_EQ(truncated.status().code(), StatusCode::kDataLoss);
  EXPECT_THAT(truncated.status().message(), HasSubstr("cut.jpg: cannot be decoded"));
}

TEST(ImageFileTest, AJpegIsDecodedReducedWhenOnlyASmallerImageIsWanted) {
  const std::vector<uint8_t> jpeg = Encoded(Gradient(1600, 1200), ".jpg");
  ImageDecodeOptions options;
  options.min_longer_side_px = 400;
  auto quarter = DecodeImageBytes(jpeg, "photo.jpg", options);
  ASSERT_TRUE(quarter.ok()) << quarter.status().ToString();
  EXPECT_EQ(quarter->cols, 400);
  EXPECT_EQ(quarter->rows, 300);
  options.min_longer_side_px = 1000;  // half would be 800: too small
  auto full = DecodeImageBytes(jpeg, "photo.jpg", options);
  ASSERT_TRUE(full.ok());
  EXPECT_EQ(full->cols, 1600);
  // PNG has no reduced decode: full size.
  options.min_longer_side_px = 400;
  auto png = DecodeImageBytes(Encoded(Gradient(1600, 1200), ".png"), "photo.png", options);
  ASSERT_TRUE(png.ok());
  EXPECT_EQ(png->cols, 1600);
}

}  // namespace
}  // namespace px
