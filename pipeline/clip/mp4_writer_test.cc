#include "pipeline/clip/mp4_writer.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <fstream>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "pipeline/clip/clip_test_util.h"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/pixdesc.h>
#include <libswscale/swscale.h>
}

namespace px::clip {
namespace {

class Mp4WriterTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = std::filesystem::temp_directory_path() /
           (std::string("px_clip_") + info->name() + "_" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path dir_;
};

cv::Mat PatternFrame(int width, int height, int index) {
  return testing::PatternFrame(width, height, index, cv::Scalar(230, 230, 240), 4);
}

// What a player sees: stream facts and every decoded frame, converted back to BGR.
struct Decoded {
  std::string codec;
  std::string pixel_format;
  int width = 0;
  int height = 0;
  double duration_s = 0;
  double fps = 0;
  std::vector<cv::Mat> frames;
};

Decoded Decode(const std::filesystem::path& path) {
  Decoded out;
  AVFormatContext* format = nullptr;
  if (avformat_open_input(&format, path.c_str(), nullptr, nullptr) < 0) return out;
  avformat_find_stream_info(format, nullptr);
  const int index = av_find_best_stream(format, AVMEDIA_TYPE_VIDEO, -1, -1, nullptr, 0);
  const AVStream* stream = format->streams[index];
  const AVCodec* decoder = avcodec_find_decoder(stream->codecpar->codec_id);
  AVCodecContext* codec = avcodec_alloc_context3(decoder);
  avcodec_parameters_to_context(codec, stream->codecpar);
  avcodec_open2(codec, decoder, nullptr);
  out.codec = avcodec_get_name(stream->codecpar->codec_id);
  out.pixel_format = av_get_pix_fmt_name(static_cast<AVPixelFormat>(stream->codecpar->format));
  out.width = stream->codecpar->width;
  out.height = stream->codecpar->height;
  out.duration_s = stream->duration * av_q2d(stream->time_base);
  out.fps = av_q2d(stream->avg_frame_rate);
  AVPacket* packet = av_packet_alloc();
  AVFrame* frame = av_frame_alloc();
  SwsContext* sws = sws_getContext(out.width,
                                   out.height,
                                   AV_PIX_FMT_YUV420P,
                                   out.width,
                                   out.height,
                                   AV_PIX_FMT_BGR24,
                                   SWS_BILINEAR,
                                   nullptr,
                                   nullptr,
                                   nullptr);
  const int* bt709 = sws_getCoefficients(SWS_CS_ITU709);
  sws_setColorspaceDetails(sws, bt709, 0, bt709, 1, 0, 1 << 16, 1 << 16);
  auto drain = [&]() {
    while (avcodec_receive_frame(codec, frame) == 0) {
      // Rows padded to 64 bytes: libswscale's SIMD output paths want aligned rows.
      const int padded = (out.width * 3 + 63) / 64 * 64;
      cv::Mat buffer(out.height + 1, padded, CV_8U);  // + a row: SIMD stores may run past the end
      uint8_t* dst[1] = {buffer.data};
      const int dst_stride[1] = {padded};
      sws_scale(sws, frame->data, frame->linesize, 0, out.height, dst, dst_stride);
      out.frames.push_back(cv::Mat(out.height, out.width, CV_8UC3, buffer.data, padded).clone());
    }
  };
  while (av_read_frame(format, packet) >= 0) {
    if (packet->stream_index == index) {
      avcodec_send_packet(codec, packet);
      drain();
    }
    av_packet_unref(packet);
  }
  avcodec_send_packet(codec, nullptr);
  drain();
  sws_freeContext(sws);
  av_frame_free(&frame);
  av_packet_free(&packet);
  avcodec_free_context(&codec);
  avformat_close_input(&format);
  return out;
}

// Top-level ISO BMFF box types in file order ("ftyp", "moov", "mdat", ...).
std::vector<std::string> TopLevelBoxes(const std::filesystem::path& path) {
  std::vector<std::string> boxes;
  std::ifstream file(path, std::ios::binary);
  const uint64_t file_size = std::filesystem::file_size(path);
  uint64_t offset = 0;
  while (offset + 8 <= file_size) {
    file.seekg(static_cast<std::streamoff>(offset));
    unsigned char header[16];
    file.read(reinterpret_cast<char*>(header), 8);
    uint64_t size = (uint64_t{header[0]} << 24) | (uint64_t{header[1]} << 16) | (uint64_t{header[2]} << 8) | header[3];
    boxes.emplace_back(reinterpret_cast<char*>(header + 4), 4);
    if (size == 1) {  // 64-bit size follows the type
      file.read(reinterpret_cast<char*>(header + 8), 8);
      size = 0;
      for (int i = 8; i < 16; ++i) size = (size << 8) | header[i];
    } else if (size == 0) {  // box runs to the end of the file
      size = file_size - offset;
    }
    if (size < 8) break;
    offset += size;
  }
  return boxes;
}

TEST_F(Mp4WriterTest, WritesAPlayableH264Clip) {
  const std::filesystem::path path = dir_ / "clip.mp4";
  Mp4Options options;
  options.fps = 25;
  StatusOr<std::unique_ptr<Mp4Writer>> writer = Mp4Writer::Open(path, 160, 120, options);
  ASSERT_TRUE(writer.ok()) << writer.status().ToString();
  std::vector<cv::Mat> input;
  for (int i = 0; i < 30; ++i) {
    input.push_back(PatternFrame(160, 120, i));
    ASSERT_TRUE((*writer)->Write(input.back()).ok());
  }
  EXPECT_EQ((*writer)->FramesWritten(), 30);
  const Status finished = (*writer)->Finish();
  ASSERT_TRUE(finished.ok()) << finished.ToString();
  EXPECT_EQ((*writer)->Finish().code(), StatusCode::kFailedPrecondition);
  EXPECT_EQ((*writer)->Write(input[0]).code(), StatusCode::kFailedPrecondition);

  const Decoded decoded = Decode(path);
  EXPECT_EQ(decoded.codec, "h264");
  EXPECT_EQ(decoded.pixel_format, "yuv420p");
  EXPECT_EQ(decoded.width, 160);
  EXPECT_EQ(decoded.height, 120);
  EXPECT_NEAR(decoded.fps, 25.0, 1e-9);
  // 30 frames at 25 fps last 1.2 s; the last frame's own duration is the one tick of slack.
  EXPECT_NEAR(decoded.duration_s, 1.2, 0.041);
  ASSERT_EQ(decoded.frames.size(), 30u);
  // CRF 20 on smooth content keeps ~40 dB; the YUV round trip alone costs ~1 level (45+ dB).
  // 30 dB still tells a frame from its neighbours (the disc moves 4 px a frame: ~20 dB apart).
  EXPECT_GT(cv::PSNR(decoded.frames.front(), input.front()), 30.0);
  EXPECT_GT(cv::PSNR(decoded.frames.back(), input.back()), 30.0);
  EXPECT_LT(cv::PSNR(decoded.frames.front(), input.back()), 25.0);

  const std::vector<std::string> boxes = TopLevelBoxes(path);
  const auto moov = std::find(boxes.begin(), boxes.end(), "moov");
  const auto mdat = std::find(boxes.begin(), boxes.end(), "mdat");
  ASSERT_NE(moov, boxes.end());
  ASSERT_NE(mdat, boxes.end());
  EXPECT_LT(moov - boxes.begin(), mdat - boxes.begin()) << "faststart: the index must precede the media data";
}

TEST_F(Mp4WriterTest, OddSizesLoseTheirLastColumnAndRow) {
  const std::filesystem::path path = dir_ / "odd.mp4";
  StatusOr<std::unique_ptr<Mp4Writer>> writer = Mp4Writer::Open(path, 101, 75, Mp4Options{});
  ASSERT_TRUE(writer.ok()) << writer.status().ToString();
  const cv::Mat frame = PatternFrame(101, 75, 0);
  for (int i = 0; i < 3; ++i) ASSERT_TRUE((*writer)->Write(frame).ok());
  ASSERT_TRUE((*writer)->Finish().ok());
  const Decoded decoded = Decode(path);
  EXPECT_EQ(decoded.width, 100);
  EXPECT_EQ(decoded.height, 74);
  ASSERT_EQ(decoded.frames.size(), 3u);
  EXPECT_GT(cv::PSNR(decoded.frames[0], frame(cv::Rect(0, 0, 100, 74)).clone()), 30.0);
}

TEST_F(Mp4WriterTest, ErrorsNameTheProblem) {
  Mp4Options options;
  options.crf = 60;
  EXPECT_NE(Mp4Writer::Open(dir_ / "a.mp4", 64, 48, options).status().message().find("clip.crf"), std::string::npos);
  options = {};
  options.preset = "warp9";
  EXPECT_NE(Mp4Writer::Open(dir_ / "a.mp4", 64, 48, options).status().message().find("warp9"), std::string::npos);
  options = {};
  options.fps = 0;
  EXPECT_EQ(Mp4Writer::Open(dir_ / "a.mp4", 64, 48, options).status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(Mp4Writer::Open(dir_ / "a.mp4", 1, 48, Mp4Options{}).status().message().find("1x48"), std::string::npos);

  const Status missing_dir = Mp4Writer::Open(dir_ / "no" / "such" / "dir.mp4", 64, 48, Mp4Options{}).status();
  EXPECT_FALSE(missing_dir.ok());
  EXPECT_NE(missing_dir.message().find("dir.mp4"), std::string::npos) << missing_dir.message();
  EXPECT_NE(missing_dir.message().find("No such file or directory"), std::string::npos) << missing_dir.message();

  StatusOr<std::unique_ptr<Mp4Writer>> writer = Mp4Writer::Open(dir_ / "b.mp4", 64, 48, Mp4Options{});
  ASSERT_TRUE(writer.ok());
  const Status wrong = (*writer)->Write(cv::Mat(48, 65, CV_8UC3, cv::Scalar::all(0)));
  EXPECT_EQ(wrong.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(wrong.message().find("65x48"), std::string::npos) << wrong.message();
  EXPECT_EQ((*writer)->Finish().code(), StatusCode::kFailedPrecondition);  // no frames
}

}  // namespace
}  // namespace px::clip
