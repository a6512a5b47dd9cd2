// Copies padded planes out of memfd-backed buffers (a stand-in for the dmabufs libcamera hands
// out: both are fds mapped at an offset) and checks the packed result byte for byte.
#include "drivers/libcamera/plane_copy.h"

#include <gtest/gtest.h>
#include <sys/mman.h>
#include <unistd.h>

#include "drivers/libcamera/mapped_plane.h"

namespace px::libcamera_driver {
namespace {

// A memfd holding `contents` from byte 0.
class Memfd {
 public:
  explicit Memfd(const std::vector<uint8_t>& contents) {
    fd_ = ::memfd_create("px-plane-test", MFD_CLOEXEC);
    EXPECT_GE(fd_, 0);
    EXPECT_EQ(::write(fd_, contents.data(), contents.size()), static_cast<ssize_t>(contents.size()));
  }
  ~Memfd() { ::close(fd_); }
  int fd() const { return fd_; }

 private:
  int fd_ = -1;
};

// Rows of `packed` (row_bytes each) laid out at `stride`, padding bytes 0xEE, after `lead` bytes of 0xAA.
std::vector<uint8_t> Pad(const std::vector<uint8_t>& packed, size_t row_bytes, size_t stride, size_t lead) {
  const size_t rows = packed.size() / row_bytes;
  std::vector<uint8_t> out(lead, 0xAA);
  for (size_t r = 0; r < rows; ++r) {
    out.insert(out.end(),
               packed.begin() + static_cast<long>(r * row_bytes),
               packed.begin() + static_cast<long>((r + 1) * row_bytes));
    out.insert(out.end(), stride - row_bytes, 0xEE);
  }
  return out;
}

std::vector<uint8_t> Pattern(size_t n, uint8_t seed) {
  std::vector<uint8_t> bytes(n);
  for (size_t i = 0; i < n; ++i) bytes[i] = static_cast<uint8_t>(seed + i * 7 + i / 13);
  return bytes;
}

TEST(PlaneCopy, PackedRgbWithPaddedRowsAtAnUnalignedOffset) {
  const int width = 10, height = 6;
  const size_t row = 3 * width, stride = 64, lead = 1000;  // 1000: not a page boundary
  const std::vector<uint8_t> packed = Pattern(row * height, 3);
  Memfd memfd(Pad(packed, row, stride, lead));
  auto mapped = MappedPlane::Map(memfd.fd(), lead, stride * height);
  ASSERT_TRUE(mapped.ok()) << mapped.status().ToString();
  EXPECT_EQ(mapped->data()[0], packed[0]);
  auto image = CopyPlanes(PixelFormat::kBgr888, width, height, {{mapped->data(), mapped->length(), stride}});
  ASSERT_TRUE(image.ok()) << image.status().ToString();
  EXPECT_TRUE(image->Validate().ok());
  EXPECT_EQ(image->bytes, packed);
}

TEST(PlaneCopy, LastRowNeedsNoPadding) {
  const int width = 4, height = 3;
  const size_t row = 2 * width, stride = 12;
  const std::vector<uint8_t> packed = Pattern(row * height, 9);
  std::vector<uint8_t> padded = Pad(packed, row, stride, 0);
  padded.resize(stride * (height - 1) + row);  // a buffer that ends right after the last pixel
  auto image = CopyPlanes(PixelFormat::kYuyv, width, height, {{padded.data(), padded.size(), stride}});
  ASSERT_TRUE(image.ok()) << image.status().ToString();
  EXPECT_EQ(image->bytes, packed);
}

TEST(PlaneCopy, Nv12AsTwoPlanesOfOneFd) {
  const int width = 8, height = 4;
  const size_t stride = 16;
  const std::vector<uint8_t> y = Pattern(width * height, 1);
  const std::vector<uint8_t> uv = Pattern(width * height / 2, 101);
  // Like a multi-planar dmabuf: Y at offset 0, UV at a page further on, both padded.
  std::vector<uint8_t> file = Pad(y, width, stride, 0);
  const size_t uv_offset = 4096;
  file.resize(uv_offset, 0x55);
  const std::vector<uint8_t> uv_padded = Pad(uv, width, stride, 0);
  file.insert(file.end(), uv_padded.begin(), uv_padded.end());
  Memfd memfd(file);
  auto y_map = MappedPlane::Map(memfd.fd(), 0, stride * height);
  auto uv_map = MappedPlane::Map(memfd.fd(), uv_offset, stride * height / 2);
  ASSERT_TRUE(y_map.ok() && uv_map.ok());
  auto image = CopyPlanes(PixelFormat::kNv12,
                          width,
                          height,
                          {{y_map->data(), y_map->length(), stride}, {uv_map->data(), uv_map->length(), stride}});
  ASSERT_TRUE(image.ok()) << image.status().ToString();
  std::vector<uint8_t> want = y;
  want.insert(want.end(), uv.begin(), uv.end());
  EXPECT_EQ(image->bytes, want);
  EXPECT_TRUE(image->Validate().ok());
}

TEST(PlaneCopy, Nv12AsOnePlaneWithUvAfterY) {
  const int width = 6, height = 4;
  const size_t stride = 8;
  std::vector<uint8_t> packed = Pattern(width * height * 3 / 2, 40);
  Memfd memfd(Pad(packed, width, stride, 0));
  auto map = MappedPlane::Map(memfd.fd(), 0, stride * height * 3 / 2);
  ASSERT_TRUE(map.ok());
  auto image = CopyPlanes(PixelFormat::kNv12, width, height, {{map->data(), map->length(), stride}});
  ASSERT_TRUE(image.ok()) << image.status().ToString();
  EXPECT_EQ(image->bytes, packed);
}

TEST(PlaneCopy, TightlyPackedBayerAndGray) {
  const std::vector<uint8_t> packed = Pattern(8 * 6, 77);
  for (PixelFormat format : {PixelFormat::kBayerRggb8, PixelFormat::kGray8}) {
    auto image = CopyPlanes(format, 8, 6, {{packed.data(), packed.size(), 0}});
    ASSERT_TRUE(image.ok()) << image.status().ToString();
    EXPECT_EQ(image->bytes, packed);
    EXPECT_EQ(image->format, format);
  }
}

TEST(PlaneCopy, AShortPlaneIsDataLossNamingTheNumbers) {
  const std::vector<uint8_t> bytes(100);
  auto image = CopyPlanes(PixelFormat::kRgb888, 10, 4, {{bytes.data(), bytes.size(), 32}});
  ASSERT_FALSE(image.ok());
  EXPECT_EQ(image.status().code(), StatusCode::kDataLoss);
  EXPECT_EQ(image.status().message(), "RGB888 10x4: plane 0 has 100 bytes, 4 rows of 30 bytes at stride 32 need 126");
}

TEST(PlaneCopy, StrideBelowTheRowIsRefused) {
  const std::vector<uint8_t> bytes(1000);
  auto image = CopyPlanes(PixelFormat::kRgb888, 10, 4, {{bytes.data(), bytes.size(), 20}});
  ASSERT_FALSE(image.ok());
  EXPECT_EQ(image.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(image.status().message().find("stride 20 is below its row size 30"), std::string::npos);
}

TEST(PlaneCopy, WrongPlaneCountAndOddSizes) {
  const std::vector<uint8_t> bytes(1000);
  PlaneView view{bytes.data(), bytes.size(), 0};
  EXPECT_EQ(CopyPlanes(PixelFormat::kRgb888, 4, 4, {view, view}).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(CopyPlanes(PixelFormat::kNv12, 5, 4, {view}).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(CopyPlanes(PixelFormat::kYuyv, 3, 2, {view}).status().code(), StatusCode::kInvalidArgument);
}

TEST(MappedPlane, BadFdOrRangeIsAnError) {
  EXPECT_FALSE(MappedPlane::Map(-1, 0, 10).ok());
  Memfd memfd(Pattern(100, 0));
  EXPECT_FALSE(MappedPlane::Map(memfd.fd(), 0, 0).ok());
  int pipe_fds[2];
  ASSERT_EQ(::pipe(pipe_fds), 0);
  auto not_mappable = MappedPlane::Map(pipe_fds[0], 0, 4096);
  ASSERT_FALSE(not_mappable.ok());
  EXPECT_NE(not_mappable.status().message().find("mmap failed"), std::string::npos) << not_mappable.status().ToString();
  ::close(pipe_fds[0]);
  ::close(pipe_fds[1]);
}

TEST(MappedPlane, MovesOwnership) {
  Memfd memfd(Pattern(5000, 5));
  auto mapped = MappedPlane::Map(memfd.fd(), 4097, 100);
  ASSERT_TRUE(mapped.ok());
  const uint8_t first = mapped->data()[0];
  EXPECT_EQ(first, Pattern(5000, 5)[4097]);
  MappedPlane moved = std::move(mapped).value();
  EXPECT_EQ(moved.data()[0], first);
  EXPECT_EQ(moved.length(), 100u);
}

}  // namespace
}  // namespace px::libcamera_driver
