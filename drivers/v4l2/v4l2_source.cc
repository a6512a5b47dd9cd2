#include "drivers/v4l2/v4l2_source.h"

#include <linux/videodev2.h>
#include <poll.h>
#include <sys/mman.h>
#include <time.h>

#include <algorithm>
#include <thread>

#include "drivers/v4l2/v4l2_formats.h"
#include "pipeline/core/log.h"
#include "pipeline/core/rig_calibration_json.h"
#include "pipeline/core/size_text.h"
#include "pipeline/io/durable_file.h"

namespace px {
namespace {

using std::chrono::milliseconds;
using std::chrono::steady_clock;

bool IsRgbOrBgr(PixelFormat format) { return format == PixelFormat::kRgb888 || format == PixelFormat::kBgr888; }

const v4l2::DeviceFormat* FindFormat(const std::vector<v4l2::DeviceFormat>& formats, uint32_t fourcc) {
  for (const auto& format : formats) {
    if (format.fourcc == fourcc) return &format;
  }
  return nullptr;
}

int64_t MonotonicNowNs() {
  timespec now{};
  clock_gettime(CLOCK_MONOTONIC, &now);
  return int64_t{now.tv_sec} * 1'000'000'000 + now.tv_nsec;
}

v4l2_buffer EmptyBuffer() {
  v4l2_buffer buffer{};
  buffer.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  buffer.memory = V4L2_MEMORY_MMAP;
  return buffer;
}

StatusOr<RigCalibration> LoadRig(const std::filesystem::path& path) {
  const std::string context = "rig calibration " + path.string();
  auto text = ReadFileToString(path);
  if (!text.ok()) return text.status().WithContext(context);
  auto rig = RigCalibrationFromJsonText(*text);
  if (!rig.ok()) return Status(StatusCode::kInvalidArgument, rig.status().message()).WithContext(context);
  if (rig->lattice.rows == 0) {
    return InvalidArgumentError(context + ": describes no lattice (an image-set rig); a lattice sensor needs one");
  }
  return rig;
}

}  // namespace

StatusOr<std::unique_ptr<V4l2Source>> OpenV4l2Source(const V4l2SourceOptions& options) {
  if (options.device.empty()) return InvalidArgumentError("v4l2: no device path given");
  if (options.buffer_count < 2 || options.buffer_count > 32) {
    return InvalidArgumentError("v4l2:" + options.device + ": buffer_count " + std::to_string(options.buffer_count) +
                                " is not in [2, 32]");
  }
  std::unique_ptr<V4l2Source> source(new V4l2Source(options));
  source->model_ = "v4l2:" + options.device;
  if (!options.rig_calibration.empty()) {
    PX_ASSIGN_OR_RETURN(RigCalibration rig, LoadRig(options.rig_calibration));
    source->rig_ = std::move(rig);
  }
  PX_RETURN_IF_ERROR(source->Open());
  return source;
}

V4l2Source::~V4l2Source() { Stop(); }

SourceDescription V4l2Source::Describe() const {
  SourceDescription description;
  description.model = model_;
  description.kind = FrameSetKind::kLatticeFrame;
  description.rig = rig_;
  return description;
}

Status V4l2Source::Open() {
  PX_ASSIGN_OR_RETURN(fd_, v4l2::OpenDevice(options_.device));
  auto info = v4l2::QueryDevice(fd_.get(), options_.device);
  if (!info.ok()) {
    fd_.Reset();
    if (info.status().code() == StatusCode::kFailedPrecondition &&
        info.status().message().rfind("v4l2:", 0) != 0) {  // QueryDevice's "not a camera" reasons
      return FailedPreconditionError(model_ + ": not a usable camera: " + info.status().message());
    }
    return info.status();
  }
  info_ = std::move(info).value();
  return OkStatus();
}

// The fourccs to try for `wanted`, best first: the same format, its RGB/BGR twin (a lossless
// swap), MJPG (decoded), then whatever else the device offers that the driver reads.
StatusOr<V4l2Source::Plan> V4l2Source::ChoosePlan(PixelFormat wanted,
                                                  const std::vector<v4l2::DeviceFormat>& formats) const {
  std::vector<Plan> candidates = {{v4l2::FourccFor(wanted), wanted}};
  if (IsRgbOrBgr(wanted)) {
    candidates.push_back(
        {v4l2::FourccFor(wanted == PixelFormat::kRgb888 ? PixelFormat::kBgr888 : PixelFormat::kRgb888), wanted});
    candidates.push_back({V4L2_PIX_FMT_MJPEG, wanted});
  }
  for (PixelFormat fallback : {PixelFormat::kBgr888,
                               PixelFormat::kRgb888,
                               PixelFormat::kYuyv,
                               PixelFormat::kNv12,
                               PixelFormat::kBayerRggb8,
                               PixelFormat::kGray8}) {
    candidates.push_back({v4l2::FourccFor(fallback), fallback});
  }
  candidates.push_back({V4L2_PIX_FMT_MJPEG, PixelFormat::kBgr888});

  for (const Plan& plan : candidates) {
    const v4l2::DeviceFormat* format = FindFormat(formats, plan.fourcc);
    if (format == nullptr) continue;
    // TRY_FMT asks without changing the device: a driver that lists a format but maps it to
    // another one on request does not get this plan.
    v4l2_format try_format{};
    try_format.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    const v4l2::FrameSize size = ChooseSize(SourceConfig{}, *format);
    try_format.fmt.pix.width = static_cast<uint32_t>(size.width);
    try_format.fmt.pix.height = static_cast<uint32_t>(size.height);
    try_format.fmt.pix.pixelformat = plan.fourcc;
    try_format.fmt.pix.field = V4L2_FIELD_NONE;
    if (v4l2::Ioctl(fd_.get(), VIDIOC_TRY_FMT, &try_format) != 0) {
      if (errno != ENOTTY)
        return v4l2::ErrnoStatus(options_.device, "VIDIOC_TRY_FMT " + v4l2::FourccName(plan.fourcc), errno);
      return plan;  // TRY_FMT is optional; S_FMT will tell
    }
    if (try_format.fmt.pix.pixelformat == plan.fourcc) return plan;
  }
  return InvalidArgumentError(model_ + ": cannot deliver " + std::string(PixelFormatName(wanted)) +
                              ": the device offers " + v4l2::DescribeFormats(formats) + "; the driver reads " +
                              v4l2::DriverFourccList());
}

v4l2::FrameSize V4l2Source::ChooseSize(const SourceConfig& wanted, const v4l2::DeviceFormat& format) const {
  // Native: the calibrated lattice's sensor size, else the largest size the device lists.
  v4l2::FrameSize native;
  if (rig_) {
    native = {rig_->lattice.sensor_width, rig_->lattice.sensor_height};
  } else if (!format.sizes.empty()) {
    native = format.sizes.front();
  } else if (format.max_size) {
    native = *format.max_size;
  } else {
    v4l2_format current{};
    current.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (v4l2::Ioctl(fd_.get(), VIDIOC_G_FMT, &current) == 0) {
      native = {static_cast<int>(current.fmt.pix.width), static_cast<int>(current.fmt.pix.height)};
    }
  }
  return {wanted.width > 0 ? wanted.width : native.width, wanted.height > 0 ? wanted.height : native.height};
}

Status V4l2Source::SetFormat(const Plan& plan, v4l2::FrameSize size) {
  v4l2_format format{};
  format.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  format.fmt.pix.width = static_cast<uint32_t>(size.width);
  format.fmt.pix.height = static_cast<uint32_t>(size.height);
  format.fmt.pix.pixelformat = plan.fourcc;
  format.fmt.pix.field = V4L2_FIELD_NONE;
  if (v4l2::Ioctl(fd_.get(), VIDIOC_S_FMT, &format) != 0) {
    return v4l2::ErrnoStatus(options_.device,
                             "VIDIOC_S_FMT " + v4l2::FourccName(plan.fourcc) + " " + SizeText(size.width, size.height),
                             errno);
  }
  const v4l2_pix_format& pix = format.fmt.pix;
  output_format_ = plan.output;
  if (pix.pixelformat != plan.fourcc) {  // the driver granted another format after all
    if (pix.pixelformat == V4L2_PIX_FMT_MJPEG) {
      output_format_ = IsRgbOrBgr(plan.output) ? plan.output : PixelFormat::kBgr888;
    } else if (auto native = v4l2::PixelFormatForFourcc(pix.pixelformat)) {
      output_format_ = (IsRgbOrBgr(*native) && IsRgbOrBgr(plan.output)) ? plan.output : *native;
    } else {
      return InvalidArgumentError(model_ + ": asked for " + v4l2::FourccName(plan.fourcc) + ", the device set " +
                                  v4l2::FourccName(pix.pixelformat) + ", which the driver cannot read");
    }
  }
  if (pix.field != V4L2_FIELD_NONE && pix.field != V4L2_FIELD_ANY) {
    return InvalidArgumentError(model_ + ": the device delivers interlaced fields (field " + std::to_string(pix.field) +
                                "); a lattice sensor must be progressive");
  }
  layout_.fourcc = pix.pixelformat;
  layout_.width = static_cast<int>(pix.width);
  layout_.height = static_cast<int>(pix.height);
  layout_.size_image = pix.sizeimage;
  layout_.bytes_per_line = pix.bytesperline;
  if (layout_.bytes_per_line == 0 && pix.pixelformat != V4L2_PIX_FMT_MJPEG) {  // some drivers leave it to us
    // One row of a one-row frame is exactly the packed row length.
    layout_.bytes_per_line = static_cast<uint32_t>(v4l2::MinimumFrameBytes({layout_.fourcc, layout_.width, 1, 0, 0}));
  }
  return OkStatus();
}

Status V4l2Source::StartStreaming() {
  v4l2_requestbuffers request{};
  request.count = static_cast<uint32_t>(options_.buffer_count);
  request.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  request.memory = V4L2_MEMORY_MMAP;
  if (v4l2::Ioctl(fd_.get(), VIDIOC_REQBUFS, &request) != 0) {
    return v4l2::ErrnoStatus(options_.device, "VIDIOC_REQBUFS", errno);
  }
  if (request.count < 2) {
    return ResourceExhaustedError(model_ + ": the device granted " + std::to_string(request.count) +
                                  " buffers, streaming needs at least 2");
  }
  buffers_.resize(request.count);
  for (uint32_t i = 0; i < request.count; ++i) {
    v4l2_buffer buffer = EmptyBuffer();
    buffer.index = i;
    if (v4l2::Ioctl(fd_.get(), VIDIOC_QUERYBUF, &buffer) != 0) {
      return v4l2::ErrnoStatus(options_.device, "VIDIOC_QUERYBUF " + std::to_string(i), errno);
    }
    void* data = mmap(nullptr, buffer.length, PROT_READ | PROT_WRITE, MAP_SHARED, fd_.get(), buffer.m.offset);
    if (data == MAP_FAILED) return v4l2::ErrnoStatus(options_.device, "mmap buffer " + std::to_string(i), errno);
    buffers_[i] = {data, buffer.length};
  }
  for (uint32_t i = 0; i < request.count; ++i) PX_RETURN_IF_ERROR(Requeue(i));
  int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (v4l2::Ioctl(fd_.get(), VIDIOC_STREAMON, &type) != 0) {
    return v4l2::ErrnoStatus(options_.device, "VIDIOC_STREAMON", errno);
  }
  streaming_ = true;
  return OkStatus();
}

void V4l2Source::ReleaseBuffers() {
  if (fd_.valid() && streaming_) {
    int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    (void)v4l2::Ioctl(fd_.get(), VIDIOC_STREAMOFF, &type);
  }
  streaming_ = false;
  const bool had_buffers = !buffers_.empty();
  for (MappedBuffer& buffer : buffers_) {
    if (buffer.data != nullptr) munmap(buffer.data, buffer.length);
  }
  buffers_.clear();
  if (fd_.valid() && had_buffers) {
    v4l2_requestbuffers request{};
    request.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    request.memory = V4L2_MEMORY_MMAP;
    (void)v4l2::Ioctl(fd_.get(), VIDIOC_REQBUFS, &request);  // count 0 frees them for other programs
  }
}

Status V4l2Source::Requeue(uint32_t index) {
  v4l2_buffer buffer = EmptyBuffer();
  buffer.index = index;
  if (v4l2::Ioctl(fd_.get(), VIDIOC_QBUF, &buffer) != 0) {
    return v4l2::ErrnoStatus(options_.device, "VIDIOC_QBUF " + std::to_string(index), errno);
  }
  return OkStatus();
}

Status V4l2Source::Vanished(Status status) {
  Logger("v4l2")->error("{}", status.message());
  vanished_ = status;
  configured_ = false;
  ReleaseBuffers();
  fd_.Reset();
  return status;
}

StatusOr<ConfigureResult> V4l2Source::Configure(const SourceConfig& wanted, SourceConfig* granted) {
  configured_ = false;
  vanished_ = OkStatus();
  ReleaseBuffers();
  if (!fd_.valid()) PX_RETURN_IF_ERROR(Open());
  Status configured = [&]() -> Status {
    PX_ASSIGN_OR_RETURN(info_.formats, v4l2::EnumerateFormats(fd_.get(), options_.device));
    PX_ASSIGN_OR_RETURN(Plan plan, ChoosePlan(wanted.pixel_format, info_.formats));
    const v4l2::FrameSize size = ChooseSize(wanted, *FindFormat(info_.formats, plan.fourcc));
    PX_RETURN_IF_ERROR(SetFormat(plan, size));
    if (Status packed = PackedImageBytes(output_format_, layout_.width, layout_.height).status(); !packed.ok()) {
      return InvalidArgumentError(model_ + ": granted " + SizeText(layout_.width, layout_.height) + " " +
                                  v4l2::FourccName(layout_.fourcc) + ": " + packed.message());
    }
    if (rig_ && (layout_.width != rig_->lattice.sensor_width || layout_.height != rig_->lattice.sensor_height)) {
      return InvalidArgumentError(model_ + ": granted " + SizeText(layout_.width, layout_.height) + ", but rig '" +
                                  rig_->rig_name + "' (" + options_.rig_calibration.string() + ") is calibrated for " +
                                  SizeText(rig_->lattice.sensor_width, rig_->lattice.sensor_height));
    }
    PX_ASSIGN_OR_RETURN(controls_, v4l2::ApplyControls(fd_.get(), options_.device, options_.controls));
    return StartStreaming();
  }();
  if (!configured.ok()) {
    if (configured.code() == StatusCode::kUnavailable) return Vanished(configured);
    ReleaseBuffers();
    return configured;
  }

  granted_ = SourceConfig{output_format_, layout_.width, layout_.height, 1};
  *granted = granted_;
  configured_ = true;
  captures_ = 0;
  const bool adjusted = output_format_ != wanted.pixel_format || (wanted.width > 0 && wanted.width != layout_.width) ||
                        (wanted.height > 0 && wanted.height != layout_.height) || wanted.shots != 1;
  std::string control_text;
  for (const auto& control : controls_) control_text += ", " + control.ToString();
  Logger("v4l2")->info("{} ({}, {}): streaming {} {} (stride {}) as {}, {} buffers{}{}",
                       model_,
                       info_.name,
                       info_.driver,
                       v4l2::FourccName(layout_.fourcc),
                       SizeText(layout_.width, layout_.height),
                       layout_.bytes_per_line,
                       PixelFormatName(output_format_),
                       buffers_.size(),
                       control_text,
                       adjusted ? "; adjusted from " + DescribeConfig(wanted) : "");
  return adjusted ? ConfigureResult::kAdjusted : ConfigureResult::kValid;
}

Status V4l2Source::DropStaleFrames() {
  std::vector<uint32_t> stale;
  for (size_t i = 0; i < buffers_.size(); ++i) {
    v4l2_buffer buffer = EmptyBuffer();
    if (v4l2::Ioctl(fd_.get(), VIDIOC_DQBUF, &buffer) != 0) {
      if (errno == EAGAIN) break;
      const int err = errno;
      if (v4l2::IsVanishedErrno(err)) return Vanished(v4l2::ErrnoStatus(options_.device, "VIDIOC_DQBUF", err));
      return v4l2::ErrnoStatus(options_.device, "VIDIOC_DQBUF", err);
    }
    stale.push_back(buffer.index);
  }
  for (uint32_t index : stale) {
    if (Status queued = Requeue(index); !queued.ok()) {
      return queued.code() == StatusCode::kUnavailable ? Vanished(queued) : queued;
    }
  }
  return OkStatus();
}

Frame V4l2Source::ToFrame(const v4l2_buffer& buffer) {
  Frame frame;
  frame.sequence = buffer.sequence;
  frame.timestamp_ns = int64_t{buffer.timestamp.tv_sec} * 1'000'000'000 + int64_t{buffer.timestamp.tv_usec} * 1000;
  if (frame.timestamp_ns == 0) frame.timestamp_ns = MonotonicNowNs();  // drivers without timestamps
  frame.image.format = output_format_;
  frame.image.width = layout_.width;
  frame.image.height = layout_.height;
  if (buffer.index >= buffers_.size()) {
    frame.status = FrameStatus::kCorrupt;
    frame.status_detail =
        "the driver returned buffer " + std::to_string(buffer.index) + " of " + std::to_string(buffers_.size());
    return frame;
  }
  if (buffer.flags & V4L2_BUF_FLAG_ERROR) {
    frame.status = FrameStatus::kCorrupt;
    frame.status_detail = "the driver flagged buffer " + std::to_string(buffer.index) + " as bad (V4L2_BUF_FLAG_ERROR)";
    return frame;
  }
  const MappedBuffer& mapped = buffers_[buffer.index];
  const size_t bytes_used = std::min<size_t>(buffer.bytesused, mapped.length);
  v4l2::Converted converted =
      v4l2::ConvertBuffer(static_cast<const uint8_t*>(mapped.data), bytes_used, layout_, output_format_);
  frame.image = std::move(converted.image);
  if (!converted.problem.empty()) {
    frame.status = FrameStatus::kCorrupt;
    frame.status_detail = "sequence " + std::to_string(buffer.sequence) + ": " + converted.problem;
    Logger("v4l2")->warn("{}: {}", model_, frame.status_detail);
  }
  return frame;
}

StatusOr<FrameSet> V4l2Source::Next(milliseconds timeout) {
  if (!vanished_.ok()) return vanished_;
  if (!configured_)
    return FailedPreconditionError(model_ + ": not configured (call Configure first, again after Stop)");
  PX_RETURN_IF_ERROR(DropStaleFrames());

  const auto deadline = steady_clock::now() + timeout;
  v4l2_buffer buffer = EmptyBuffer();
  bool poll_said_ready = false;
  while (v4l2::Ioctl(fd_.get(), VIDIOC_DQBUF, &buffer) != 0) {
    const int err = errno;
    if (err != EAGAIN) {
      if (v4l2::IsVanishedErrno(err)) return Vanished(v4l2::ErrnoStatus(options_.device, "VIDIOC_DQBUF", err));
      return v4l2::ErrnoStatus(options_.device, "VIDIOC_DQBUF", err);
    }
    const auto now = steady_clock::now();
    if (now >= deadline) {
      return DeadlineExceededError(model_ + ": no frame within " + std::to_string(timeout.count()) + " ms");
    }
    // poll(2) may say "ready" while DQBUF has nothing (umockdev nodes always poll ready): then
    // wait a little ourselves, so that the loop never spins.
    if (poll_said_ready) std::this_thread::sleep_for(std::min<steady_clock::duration>(milliseconds(1), deadline - now));
    pollfd wait{fd_.get(), POLLIN, 0};
    const auto left = std::chrono::duration_cast<milliseconds>(deadline - steady_clock::now()).count();
    poll_said_ready = poll(&wait, 1, static_cast<int>(std::clamp<int64_t>(left, 0, 100))) > 0;
    buffer = EmptyBuffer();
  }

  FrameSet frames;
  frames.kind = FrameSetKind::kLatticeFrame;
  frames.capture_id = ++captures_;
  frames.frames.push_back(ToFrame(buffer));
  if (Status queued = Requeue(buffer.index); !queued.ok()) {
    // This frame is good; the next call reports the problem.
    if (queued.code() == StatusCode::kUnavailable) {
      (void)Vanished(queued);
    } else {
      Logger("v4l2")->warn("{}", queued.message());
    }
  }
  (void)CheckFrameSet(granted_, &frames);  // marks a frame that does not match what was granted
  return frames;
}

void V4l2Source::Stop() {
  ReleaseBuffers();
  fd_.Reset();
  configured_ = false;
  vanished_ = OkStatus();
}

}  // namespace px
