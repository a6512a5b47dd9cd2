// An emulated V4L2 camera for tests: a umockdev testbed node (a regular file, so the driver's
// mmap works) with an ioctl handler that answers like a single-planar capture driver built on
// videobuf2: QUERYCAP, ENUM_FMT, ENUM_FRAMESIZES, G/S/TRY_FMT, REQBUFS (growing the node file),
// QUERYBUF, QBUF, DQBUF (writing the frame into the node file at the buffer's offset),
// STREAMON/OFF, QUERYCTRL/G_CTRL/S_CTRL; anything else answers ENOTTY. It serves one real
// image (a simulated lattice frame) encoded in whatever format the client negotiated, with
// padded rows, and can vanish, stall or deliver a short buffer on request.
//
// The process must run with LD_PRELOAD=libumockdev-preload.so.0 (RunTestsUnderUmockdev re-execs
// itself with it; ctest also sets it).
#pragma once

#include <linux/videodev2.h>

#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "pipeline/core/status.h"

typedef struct _UMockdevTestbed UMockdevTestbed;
typedef struct _UMockdevIoctlBase UMockdevIoctlBase;
typedef struct _UMockdevIoctlClient UMockdevIoctlClient;

namespace px::testing {

struct EmulatedCameraOptions {
  std::string node = "video0";                  // appears as /dev/<node>
  std::string card = "Parallax emulated Pop9";  // QUERYCAP's card holds 31 characters
  std::string driver = "px_emulated";
  std::string bus_info = "platform:px-emulated";
  uint32_t device_caps = V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_STREAMING;
  // Offered formats, in ENUM_FMT order.
  std::vector<uint32_t> fourccs = {V4L2_PIX_FMT_YUYV,
                                   V4L2_PIX_FMT_NV12,
                                   V4L2_PIX_FMT_MJPEG,
                                   V4L2_PIX_FMT_SRGGB8,
                                   V4L2_PIX_FMT_BGR24,
                                   V4L2_PIX_FMT_GREY};
  std::vector<cv::Size> sizes;  // discrete sizes for every format; empty = the served image's size only
  int row_padding = 24;         // bytes after each row (bytesperline > packed row), filled with 0xEE
  bool controls = true;         // auto exposure, exposure (1..5000) and gain (0..255)
  uint32_t max_buffers = 8;
};

class EmulatedV4l2Camera {
 public:
  EmulatedV4l2Camera(const EmulatedCameraOptions& options, cv::Mat frame_bgr, std::string node_file);
  ~EmulatedV4l2Camera();

  std::string DevicePath() const { return "/dev/" + options_.node; }

  // Faults, effective from the next ioctl.
  void SetVanished(bool vanished);                // every ioctl fails with ENODEV (unplugged)
  void SetStalled(bool stalled);                  // DQBUF answers EAGAIN: no frame arrives
  void ShortenFrames(uint32_t bytes_used);        // frames carry only this many bytes (0 = whole again)
  void SetDriverFourccOverride(uint32_t fourcc);  // S_FMT grants this fourcc whatever was asked (0 = off)

  // What the client negotiated and what it was served.
  uint32_t Fourcc() const;
  cv::Size Size() const;
  uint32_t BytesPerLine() const;
  cv::Mat SourceBgr() const;                 // the served image at the negotiated size (BGR)
  std::vector<uint8_t> PackedFrame() const;  // that image encoded in the negotiated format, rows unpadded
  uint64_t FramesServed() const;
  bool Streaming() const;
  int32_t Control(uint32_t id) const;           // current value of a control
  std::vector<uint32_t> ControlWrites() const;  // ids written with S_CTRL, in order

  // The handler (umockdev's thread); public for the C callback.
  bool Handle(UMockdevIoctlClient* client);
  void ClientGone(UMockdevIoctlClient* client);
  UMockdevIoctlBase* handler() const { return handler_; }

 private:
  struct ControlInfo {
    v4l2_queryctrl query;
    int32_t value;
  };
  struct Answer {
    long result = 0;
    int err = 0;
  };
  static Answer Ok() { return {0, 0}; }
  static Answer Fail(int err) { return {-1, err}; }

  Answer Dispatch(UMockdevIoctlClient* client, unsigned long request, void* arg);
  void Adjust(v4l2_pix_format* pix) const;  // what TRY_FMT and S_FMT grant
  void PrepareFrame();                      // encodes the image for the current format
  void ReleaseBuffers();
  bool Owned(UMockdevIoctlClient* client) const { return owner_ == nullptr || owner_ == client; }

  EmulatedCameraOptions options_;
  cv::Mat frame_bgr_;
  std::string node_file_;  // the testbed's regular file behind /dev/<node>
  UMockdevIoctlBase* handler_ = nullptr;

  mutable std::mutex mutex_;
  v4l2_pix_format format_{};
  cv::Mat sized_bgr_;
  std::vector<uint8_t> packed_;           // unpadded encoding
  std::vector<uint8_t> frame_;            // what DQBUF writes (padded rows, or the JPEG)
  UMockdevIoctlClient* owner_ = nullptr;  // the file handle that holds the buffers (vb2's owner)
  uint32_t buffer_count_ = 0;
  uint32_t buffer_size_ = 0;
  std::vector<uint32_t> queued_;  // buffer indices in QBUF order
  bool streaming_ = false;
  uint32_t sequence_ = 0;
  uint64_t served_ = 0;
  bool vanished_ = false;
  bool stalled_ = false;
  uint32_t short_frames_ = 0;
  uint32_t fourcc_override_ = 0;
  std::map<uint32_t, ControlInfo> controls_;
  std::vector<uint32_t> control_writes_;
};

// One umockdev testbed holding any number of emulated cameras (and plain nodes).
class EmulatedV4l2Testbed {
 public:
  // UNAVAILABLE, with the reason, when the process does not run under the umockdev preload.
  static StatusOr<std::unique_ptr<EmulatedV4l2Testbed>> Create();
  ~EmulatedV4l2Testbed();

  // Adds /dev/<options.node> serving `frame_bgr` (CV_8UC3).
  StatusOr<EmulatedV4l2Camera*> AddCamera(const EmulatedCameraOptions& options, const cv::Mat& frame_bgr);
  // Adds /dev/<node> with no ioctl handler: every ioctl fails, like a node that is not V4L2.
  Status AddPlainNode(const std::string& node);

 private:
  EmulatedV4l2Testbed() = default;
  Status AddNode(const std::string& node);

  UMockdevTestbed* testbed_ = nullptr;
  std::string root_;
  std::vector<std::unique_ptr<EmulatedV4l2Camera>> cameras_;
};

// main() for test binaries that use emulated devices: re-execs the binary with the umockdev
// preload library in LD_PRELOAD when it is missing, then runs the tests.
int RunTestsUnderUmockdev(int argc, char** argv);

}  // namespace px::testing
