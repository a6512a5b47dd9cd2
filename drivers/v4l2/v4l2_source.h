// A V4L2 camera (a multi-lens sensor on /dev/videoN) as a FrameSource: format negotiation,
// mmap streaming, exposure and gain, and conversion to the pipeline's pixel formats.
//
// Configure() opens the node if needed, picks a fourcc for the wanted px::PixelFormat (the same
// format; else RGB3/BGR3 swapped; else MJPG decoded, for RGB888/BGR888; else the device's
// best readable format, reported as kAdjusted), sets it with TRY_FMT/S_FMT, applies the
// controls, maps buffers and starts streaming. Next() drops frames that were waiting in the
// queue (a press wants a frame taken after it), then waits for a fresh one until the timeout.
#pragma once

#include <linux/videodev2.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "drivers/source/frame_source.h"
#include "drivers/v4l2/v4l2_controls.h"
#include "drivers/v4l2/v4l2_convert.h"
#include "drivers/v4l2/v4l2_discovery.h"
#include "drivers/v4l2/v4l2_io.h"

namespace px {

struct V4l2SourceOptions {
  std::string device = "/dev/video0";
  std::filesystem::path rig_calibration;  // rig calibration JSON (pipeline/core/rig_calibration_json.h); "" = none
  v4l2::ControlSettings controls;         // exposure, gain, auto exposure; unset = leave as the device has them
  int buffer_count = 4;                   // mmap buffers to request, [2, 32]
};

class V4l2Source final : public FrameSource {
 public:
  ~V4l2Source() override;

  std::string_view Name() const override { return "v4l2"; }
  // model "v4l2:/dev/video0", a lattice frame, and the rig calibration from the options' file.
  SourceDescription Describe() const override;
  StatusOr<ConfigureResult> Configure(const SourceConfig& wanted, SourceConfig* granted) override;
  StatusOr<FrameSet> Next(std::chrono::milliseconds timeout) override;
  void Stop() override;

  // The device as QUERYCAP and ENUM_FMT described it when it was opened.
  const v4l2::DeviceInfo& Info() const { return info_; }
  // Exposure, gain and auto exposure as last applied and read back (empty before Configure).
  const std::vector<v4l2::ControlState>& Controls() const { return controls_; }
  // What the device delivers: fourcc, size and stride as granted by S_FMT.
  const v4l2::BufferLayout& Layout() const { return layout_; }

 private:
  friend StatusOr<std::unique_ptr<V4l2Source>> OpenV4l2Source(const V4l2SourceOptions& options);
  struct MappedBuffer {
    void* data = nullptr;
    size_t length = 0;
  };
  struct Plan {  // a fourcc to ask the device for, and the pipeline format it becomes
    uint32_t fourcc = 0;
    PixelFormat output = PixelFormat::kBgr888;
  };

  explicit V4l2Source(V4l2SourceOptions options) : options_(std::move(options)) {}

  Status Open();
  StatusOr<Plan> ChoosePlan(PixelFormat wanted, const std::vector<v4l2::DeviceFormat>& formats) const;
  v4l2::FrameSize ChooseSize(const SourceConfig& wanted, const v4l2::DeviceFormat& format) const;
  Status SetFormat(const Plan& plan, v4l2::FrameSize size);
  Status StartStreaming();
  void ReleaseBuffers();  // STREAMOFF, munmap, REQBUFS 0; errors ignored (the device may be gone)
  Status Requeue(uint32_t index);
  // Marks the source as gone (the camera vanished) and releases what it can.
  Status Vanished(Status status);
  // Frames waiting since before this capture: dequeued and queued again without being read.
  Status DropStaleFrames();
  Frame ToFrame(const ::v4l2_buffer& buffer);

  V4l2SourceOptions options_;
  std::string model_;
  std::optional<RigCalibration> rig_;
  v4l2::UniqueFd fd_;
  v4l2::DeviceInfo info_;
  std::vector<v4l2::ControlState> controls_;
  v4l2::BufferLayout layout_;
  PixelFormat output_format_ = PixelFormat::kBgr888;
  SourceConfig granted_;
  std::vector<MappedBuffer> buffers_;
  bool streaming_ = false;
  bool configured_ = false;
  Status vanished_;  // not OK once the camera went away, until the next Configure
  uint64_t captures_ = 0;
};

// Opens the device and checks it is a single-planar streaming capture device (errors as
// v4l2::ErrnoStatus: NOT_FOUND for a missing node, FAILED_PRECONDITION when another program
// holds it or it is not a camera), and loads the rig calibration file if one is named
// (errors name the file and field). Configure() before Next().
StatusOr<std::unique_ptr<V4l2Source>> OpenV4l2Source(const V4l2SourceOptions& options);

}  // namespace px
