#include "tests/drivers/emulated_v4l2_device.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <linux/version.h>
#include <umockdev.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <utility>

#include "pipeline/core/pixel_format.h"

namespace px::testing {
namespace {

gboolean OnHandleIoctl(UMockdevIoctlBase*, UMockdevIoctlClient* client, gpointer self) {
  return static_cast<EmulatedV4l2Camera*>(self)->Handle(client) ? TRUE : FALSE;
}

void OnClientVanished(UMockdevIoctlBase*, UMockdevIoctlClient* client, gpointer self) {
  static_cast<EmulatedV4l2Camera*>(self)->ClientGone(client);
}

void CopyString(const std::string& text, __u8* out, size_t size) {
  std::strncpy(reinterpret_cast<char*>(out), text.c_str(), size - 1);
}

// Bytes of one row of the first plane, and the number of rows (NV12's UV rows included).
size_t RowBytes(uint32_t fourcc, int width) {
  if (fourcc == V4L2_PIX_FMT_RGB24 || fourcc == V4L2_PIX_FMT_BGR24) return static_cast<size_t>(width) * 3;
  if (fourcc == V4L2_PIX_FMT_YUYV) return static_cast<size_t>(width) * 2;
  return static_cast<size_t>(width);
}
size_t Rows(uint32_t fourcc, int height) {
  return fourcc == V4L2_PIX_FMT_NV12 ? static_cast<size_t>(height) * 3 / 2 : static_cast<size_t>(height);
}

std::optional<PixelFormat> PipelineFormat(uint32_t fourcc) {
  switch (fourcc) {
    case V4L2_PIX_FMT_RGB24:
      return PixelFormat::kRgb888;
    case V4L2_PIX_FMT_BGR24:
      return PixelFormat::kBgr888;
    case V4L2_PIX_FMT_GREY:
      return PixelFormat::kGray8;
    case V4L2_PIX_FMT_YUYV:
      return PixelFormat::kYuyv;
    case V4L2_PIX_FMT_NV12:
      return PixelFormat::kNv12;
    case V4L2_PIX_FMT_SRGGB8:
      return PixelFormat::kBayerRggb8;
    default:
      return std::nullopt;
  }
}

std::string FourccText(uint32_t fourcc) {
  std::string text;
  for (int i = 0; i < 4; ++i) text += static_cast<char>((fourcc >> (8 * i)) & 0xff);
  return text;
}

v4l2_queryctrl IntegerControl(uint32_t id, const char* name, int32_t min, int32_t max, int32_t def) {
  v4l2_queryctrl query{};
  query.id = id;
  query.type = V4L2_CTRL_TYPE_INTEGER;
  CopyString(name, query.name, sizeof(query.name));
  query.minimum = min;
  query.maximum = max;
  query.step = 1;
  query.default_value = def;
  return query;
}

// Whether umockdev's preload library is mapped into this process (umockdev_in_mock_environment
// looks at $LD_PRELOAD, which does not say whether the library was actually loaded).
bool PreloadIsLoaded() {
  std::ifstream maps("/proc/self/maps");
  std::string line;
  while (std::getline(maps, line)) {
    if (line.find("libumockdev-preload") != std::string::npos) return true;
  }
  return false;
}

}  // namespace

EmulatedV4l2Camera::EmulatedV4l2Camera(const EmulatedCameraOptions& options, cv::Mat frame_bgr, std::string node_file)
    : options_(options), frame_bgr_(std::move(frame_bgr)), node_file_(std::move(node_file)) {
  if (options_.sizes.empty()) options_.sizes.push_back(frame_bgr_.size());
  if (options_.controls) {
    v4l2_queryctrl auto_exposure = IntegerControl(V4L2_CID_EXPOSURE_AUTO, "Auto Exposure", 0, 3, V4L2_EXPOSURE_AUTO);
    auto_exposure.type = V4L2_CTRL_TYPE_MENU;
    controls_[V4L2_CID_EXPOSURE_AUTO] = {auto_exposure, V4L2_EXPOSURE_AUTO};
    controls_[V4L2_CID_EXPOSURE_ABSOLUTE] = {
        IntegerControl(V4L2_CID_EXPOSURE_ABSOLUTE, "Exposure Time, Absolute", 1, 5000, 156), 156};
    controls_[V4L2_CID_GAIN] = {IntegerControl(V4L2_CID_GAIN, "Gain", 0, 255, 32), 32};
  }
  // The first format at the first size, as a driver starts.
  format_.pixelformat = options_.fourccs.empty() ? 0 : options_.fourccs.front();
  format_.width = static_cast<uint32_t>(options_.sizes.front().width);
  format_.height = static_cast<uint32_t>(options_.sizes.front().height);
  Adjust(&format_);
  PrepareFrame();
  handler_ = UMOCKDEV_IOCTL_BASE(g_object_new(UMOCKDEV_TYPE_IOCTL_BASE, nullptr));
  g_signal_connect(handler_, "handle-ioctl", G_CALLBACK(OnHandleIoctl), this);
  g_signal_connect(handler_, "client-vanished", G_CALLBACK(OnClientVanished), this);
}

EmulatedV4l2Camera::~EmulatedV4l2Camera() {
  if (handler_ != nullptr) {
    g_signal_handlers_disconnect_by_data(handler_, this);
    g_object_unref(handler_);
  }
}

void EmulatedV4l2Camera::SetVanished(bool vanished) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (vanished_ && !vanished) ReleaseBuffers();  // plugged back in: a fresh device, no owner
  vanished_ = vanished;
}
void EmulatedV4l2Camera::SetStalled(bool stalled) {
  std::lock_guard<std::mutex> lock(mutex_);
  stalled_ = stalled;
}
void EmulatedV4l2Camera::ShortenFrames(uint32_t bytes_used) {
  std::lock_guard<std::mutex> lock(mutex_);
  short_frames_ = bytes_used;
}
void EmulatedV4l2Camera::SetDriverFourccOverride(uint32_t fourcc) {
  std::lock_guard<std::mutex> lock(mutex_);
  fourcc_override_ = fourcc;
}
uint32_t EmulatedV4l2Camera::Fourcc() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return format_.pixelformat;
}
cv::Size EmulatedV4l2Camera::Size() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return {static_cast<int>(format_.width), static_cast<int>(format_.height)};
}
uint32_t EmulatedV4l2Camera::BytesPerLine() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return format_.bytesperline;
}
cv::Mat EmulatedV4l2Camera::SourceBgr() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return sized_bgr_.clone();
}
std::vector<uint8_t> EmulatedV4l2Camera::PackedFrame() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return packed_;
}
uint64_t EmulatedV4l2Camera::FramesServed() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return served_;
}
bool EmulatedV4l2Camera::Streaming() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return streaming_;
}
int32_t EmulatedV4l2Camera::Control(uint32_t id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = controls_.find(id);
  return it == controls_.end() ? -1 : it->second.value;
}
std::vector<uint32_t> EmulatedV4l2Camera::ControlWrites() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return control_writes_;
}

void EmulatedV4l2Camera::Adjust(v4l2_pix_format* pix) const {
  bool offered = false;
  for (uint32_t fourcc : options_.fourccs) offered |= fourcc == pix->pixelformat;
  if (!offered && !options_.fourccs.empty()) pix->pixelformat = options_.fourccs.front();
  // The nearest offered size, as drivers do.
  cv::Size best = options_.sizes.front();
  int64_t best_distance = -1;
  for (const cv::Size& size : options_.sizes) {
    const int64_t dw = int64_t{size.width} - pix->width, dh = int64_t{size.height} - pix->height;
    const int64_t distance = dw * dw + dh * dh;
    if (best_distance < 0 || distance < best_distance) {
      best = size;
      best_distance = distance;
    }
  }
  pix->width = static_cast<uint32_t>(best.width);
  pix->height = static_cast<uint32_t>(best.height);
  pix->field = V4L2_FIELD_NONE;
  pix->colorspace = V4L2_COLORSPACE_SRGB;
  if (pix->pixelformat == V4L2_PIX_FMT_MJPEG) {
    pix->bytesperline = 0;
    pix->sizeimage = pix->width * pix->height * 2;  // an upper bound, like uvcvideo's
  } else {
    pix->bytesperline = static_cast<uint32_t>(RowBytes(pix->pixelformat, best.width) + options_.row_padding);
    pix->sizeimage = static_cast<uint32_t>(pix->bytesperline * Rows(pix->pixelformat, best.height));
  }
}

void EmulatedV4l2Camera::PrepareFrame() {
  const cv::Size size(static_cast<int>(format_.width), static_cast<int>(format_.height));
  if (frame_bgr_.size() == size) {
    sized_bgr_ = frame_bgr_.clone();
  } else {
    cv::resize(frame_bgr_, sized_bgr_, size, 0, 0, cv::INTER_AREA);
  }
  packed_.clear();
  frame_.clear();
  if (format_.pixelformat == V4L2_PIX_FMT_MJPEG) {
    cv::imencode(".jpg", sized_bgr_, frame_, {cv::IMWRITE_JPEG_QUALITY, 95});
    packed_ = frame_;
    return;
  }
  auto format = PipelineFormat(format_.pixelformat);
  if (!format) return;
  auto raw = FromBgr(sized_bgr_, *format);
  if (!raw.ok()) return;
  packed_ = raw->bytes;
  const size_t row_bytes = RowBytes(format_.pixelformat, size.width);
  const size_t rows = Rows(format_.pixelformat, size.height);
  frame_.assign(format_.sizeimage, 0xEE);  // padding a driver must skip
  for (size_t r = 0; r < rows; ++r) {
    std::memcpy(frame_.data() + r * format_.bytesperline, packed_.data() + r * row_bytes, row_bytes);
  }
}

void EmulatedV4l2Camera::ReleaseBuffers() {
  owner_ = nullptr;
  buffer_count_ = 0;
  queued_.clear();
  streaming_ = false;
}

void EmulatedV4l2Camera::ClientGone(UMockdevIoctlClient* client) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (owner_ == client) ReleaseBuffers();  // closing the file handle frees its buffers
}

bool EmulatedV4l2Camera::Handle(UMockdevIoctlClient* client) {
  const unsigned long request = umockdev_ioctl_client_get_request(client);
  const size_t size = _IOC_SIZE(request);
  UMockdevIoctlData* data = nullptr;
  if (size > 0) {
    GError* error = nullptr;
    data = umockdev_ioctl_data_resolve(umockdev_ioctl_client_get_arg(client), 0, size, &error);
    if (data == nullptr) {
      if (error != nullptr) g_error_free(error);
      umockdev_ioctl_client_complete(client, -1, EFAULT);
      return true;
    }
  }
  Answer answer;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    answer = vanished_ ? Fail(ENODEV) : Dispatch(client, request, data != nullptr ? data->data : nullptr);
  }
  umockdev_ioctl_client_complete(client, answer.result, answer.err);
  if (data != nullptr) umockdev_ioctl_data_unref(data);
  return true;
}

EmulatedV4l2Camera::Answer EmulatedV4l2Camera::Dispatch(UMockdevIoctlClient* client, unsigned long request, void* arg) {
  switch (request) {
    case VIDIOC_QUERYCAP: {
      auto* cap = static_cast<v4l2_capability*>(arg);
      *cap = {};
      CopyString(options_.driver, cap->driver, sizeof(cap->driver));
      CopyString(options_.card, cap->card, sizeof(cap->card));
      CopyString(options_.bus_info, cap->bus_info, sizeof(cap->bus_info));
      cap->version = KERNEL_VERSION(6, 1, 0);
      cap->device_caps = options_.device_caps;
      cap->capabilities = options_.device_caps | V4L2_CAP_DEVICE_CAPS;
      return Ok();
    }
    case VIDIOC_ENUM_FMT: {
      auto* desc = static_cast<v4l2_fmtdesc*>(arg);
      if (desc->type != V4L2_BUF_TYPE_VIDEO_CAPTURE || desc->index >= options_.fourccs.size()) return Fail(EINVAL);
      const uint32_t fourcc = options_.fourccs[desc->index];
      desc->pixelformat = fourcc;
      desc->flags = fourcc == V4L2_PIX_FMT_MJPEG ? V4L2_FMT_FLAG_COMPRESSED : 0;
      CopyString("Emulated " + FourccText(fourcc), desc->description, sizeof(desc->description));
      return Ok();
    }
    case VIDIOC_ENUM_FRAMESIZES: {
      auto* size = static_cast<v4l2_frmsizeenum*>(arg);
      bool offered = false;
      for (uint32_t fourcc : options_.fourccs) offered |= fourcc == size->pixel_format;
      if (!offered || size->index >= options_.sizes.size()) return Fail(EINVAL);
      size->type = V4L2_FRMSIZE_TYPE_DISCRETE;
      size->discrete.width = static_cast<uint32_t>(options_.sizes[size->index].width);
      size->discrete.height = static_cast<uint32_t>(options_.sizes[size->index].height);
      return Ok();
    }
    case VIDIOC_G_FMT: {
      auto* format = static_cast<v4l2_format*>(arg);
      if (format->type != V4L2_BUF_TYPE_VIDEO_CAPTURE) return Fail(EINVAL);
      format->fmt.pix = format_;
      return Ok();
    }
    case VIDIOC_TRY_FMT:
    case VIDIOC_S_FMT: {
      auto* format = static_cast<v4l2_format*>(arg);
      if (format->type != V4L2_BUF_TYPE_VIDEO_CAPTURE) return Fail(EINVAL);
      if (request == VIDIOC_S_FMT) {
        if (buffer_count_ > 0) return Fail(EBUSY);  // vb2: no format change while buffers exist
        if (fourcc_override_ != 0) format->fmt.pix.pixelformat = fourcc_override_;
      }
      Adjust(&format->fmt.pix);
      if (request == VIDIOC_S_FMT) {
        format_ = format->fmt.pix;
        PrepareFrame();
      }
      return Ok();
    }
    case VIDIOC_REQBUFS: {
      auto* request_buffers = static_cast<v4l2_requestbuffers*>(arg);
      if (request_buffers->type != V4L2_BUF_TYPE_VIDEO_CAPTURE || request_buffers->memory != V4L2_MEMORY_MMAP) {
        return Fail(EINVAL);
      }
      if (!Owned(client)) return Fail(EBUSY);
      if (streaming_) return Fail(EBUSY);
      if (request_buffers->count == 0) {
        ReleaseBuffers();
        return Ok();
      }
      const uint32_t page = static_cast<uint32_t>(sysconf(_SC_PAGESIZE));
      buffer_count_ = std::min(request_buffers->count, options_.max_buffers);
      buffer_size_ = (format_.sizeimage + page - 1) / page * page;
      if (truncate(node_file_.c_str(), static_cast<off_t>(buffer_count_) * buffer_size_) != 0) return Fail(ENOMEM);
      owner_ = client;
      queued_.clear();
      request_buffers->count = buffer_count_;
      return Ok();
    }
    case VIDIOC_QUERYBUF:
    case VIDIOC_QBUF:
    case VIDIOC_DQBUF: {
      auto* buffer = static_cast<v4l2_buffer*>(arg);
      if (buffer->type != V4L2_BUF_TYPE_VIDEO_CAPTURE) return Fail(EINVAL);
      if (!Owned(client)) return Fail(EBUSY);
      if (request == VIDIOC_DQBUF) {
        if (!streaming_) return Fail(EINVAL);
        if (stalled_ || queued_.empty()) return Fail(EAGAIN);
        const uint32_t index = queued_.front();
        queued_.erase(queued_.begin());
        uint32_t bytes_used = static_cast<uint32_t>(frame_.size());
        if (short_frames_ > 0) bytes_used = std::min(bytes_used, short_frames_);
        const int fd = open(node_file_.c_str(), O_WRONLY | O_CLOEXEC);
        if (fd < 0) return Fail(EIO);
        const ssize_t written = pwrite(fd, frame_.data(), bytes_used, static_cast<off_t>(index) * buffer_size_);
        close(fd);
        if (written != static_cast<ssize_t>(bytes_used)) return Fail(EIO);
        timespec now{};
        clock_gettime(CLOCK_MONOTONIC, &now);
        *buffer = {};
        buffer->index = index;
        buffer->type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        buffer->memory = V4L2_MEMORY_MMAP;
        buffer->bytesused = bytes_used;
        buffer->length = buffer_size_;
        buffer->m.offset = index * buffer_size_;
        buffer->field = V4L2_FIELD_NONE;
        buffer->flags = V4L2_BUF_FLAG_MAPPED | V4L2_BUF_FLAG_DONE | V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC;
        buffer->timestamp.tv_sec = now.tv_sec;
        buffer->timestamp.tv_usec = now.tv_nsec / 1000;
        buffer->sequence = sequence_++;
        ++served_;
        return Ok();
      }
      if (buffer->memory != V4L2_MEMORY_MMAP || buffer->index >= buffer_count_) return Fail(EINVAL);
      bool queued = false;
      for (uint32_t index : queued_) queued |= index == buffer->index;
      if (request == VIDIOC_QBUF) {
        if (queued) return Fail(EINVAL);
        queued_.push_back(buffer->index);
      }
      buffer->length = buffer_size_;
      buffer->m.offset = buffer->index * buffer_size_;
      buffer->flags = V4L2_BUF_FLAG_MAPPED | (queued || request == VIDIOC_QBUF ? V4L2_BUF_FLAG_QUEUED : 0);
      return Ok();
    }
    case VIDIOC_STREAMON:
    case VIDIOC_STREAMOFF: {
      if (*static_cast<int*>(arg) != V4L2_BUF_TYPE_VIDEO_CAPTURE) return Fail(EINVAL);
      if (!Owned(client)) return Fail(EBUSY);
      if (request == VIDIOC_STREAMON) {
        if (buffer_count_ == 0) return Fail(EINVAL);
        if (!streaming_) sequence_ = 0;
        streaming_ = true;
      } else {
        streaming_ = false;
        queued_.clear();  // STREAMOFF returns every buffer to the application
      }
      return Ok();
    }
    case VIDIOC_QUERYCTRL: {
      auto* query = static_cast<v4l2_queryctrl*>(arg);
      auto it = controls_.find(query->id);
      if (it == controls_.end()) return Fail(EINVAL);
      *query = it->second.query;
      const bool manual =
          controls_.count(V4L2_CID_EXPOSURE_AUTO) && controls_.at(V4L2_CID_EXPOSURE_AUTO).value == V4L2_EXPOSURE_MANUAL;
      if (query->id == V4L2_CID_EXPOSURE_ABSOLUTE && !manual) query->flags |= V4L2_CTRL_FLAG_INACTIVE;
      return Ok();
    }
    case VIDIOC_G_CTRL:
    case VIDIOC_S_CTRL: {
      auto* control = static_cast<v4l2_control*>(arg);
      auto it = controls_.find(control->id);
      if (it == controls_.end()) return Fail(EINVAL);
      if (request == VIDIOC_G_CTRL) {
        control->value = it->second.value;
        return Ok();
      }
      const v4l2_queryctrl& query = it->second.query;
      if (control->value < query.minimum || control->value > query.maximum) return Fail(ERANGE);
      if (control->id == V4L2_CID_EXPOSURE_AUTO && control->value != V4L2_EXPOSURE_AUTO &&
          control->value != V4L2_EXPOSURE_MANUAL) {
        return Fail(EINVAL);  // like many webcams: only auto and manual
      }
      // uvcvideo refuses a fixed exposure while auto exposure is on.
      if (control->id == V4L2_CID_EXPOSURE_ABSOLUTE &&
          controls_[V4L2_CID_EXPOSURE_AUTO].value != V4L2_EXPOSURE_MANUAL) {
        return Fail(EACCES);
      }
      it->second.value = control->value;
      control_writes_.push_back(control->id);
      return Ok();
    }
    default:
      return Fail(ENOTTY);
  }
}

StatusOr<std::unique_ptr<EmulatedV4l2Testbed>> EmulatedV4l2Testbed::Create() {
  if (!PreloadIsLoaded()) {
    return UnavailableError("not running under umockdev: start the test with LD_PRELOAD=libumockdev-preload.so.0");
  }
  std::unique_ptr<EmulatedV4l2Testbed> testbed(new EmulatedV4l2Testbed());
  testbed->testbed_ = umockdev_testbed_new();
  gchar* root = umockdev_testbed_get_root_dir(testbed->testbed_);
  testbed->root_ = root;
  g_free(root);
  return testbed;
}

EmulatedV4l2Testbed::~EmulatedV4l2Testbed() {
  for (const auto& camera : cameras_) {
    umockdev_testbed_detach_ioctl(testbed_, camera->DevicePath().c_str(), nullptr);
  }
  cameras_.clear();
  if (testbed_ != nullptr) g_object_unref(testbed_);
}

Status EmulatedV4l2Testbed::AddNode(const std::string& node) {
  // "N: video0=00": a node with contents is a regular file, so mmap works on it.
  const std::string description = "P: /devices/virtual/video4linux/" + node + "\nN: " + node +
                                  "=00\nE: SUBSYSTEM=video4linux\nE: DEVNAME=/dev/" + node + "\n";
  GError* error = nullptr;
  if (!umockdev_testbed_add_from_string(testbed_, description.c_str(), &error)) {
    Status status = InternalError("umockdev: cannot add /dev/" + node + ": " + (error ? error->message : "?"));
    if (error != nullptr) g_error_free(error);
    return status;
  }
  return OkStatus();
}

Status EmulatedV4l2Testbed::AddPlainNode(const std::string& node) { return AddNode(node); }

StatusOr<EmulatedV4l2Camera*> EmulatedV4l2Testbed::AddCamera(const EmulatedCameraOptions& options,
                                                             const cv::Mat& frame_bgr) {
  if (frame_bgr.type() != CV_8UC3 || frame_bgr.empty())
    return InvalidArgumentError("emulated camera: want a BGR image");
  PX_RETURN_IF_ERROR(AddNode(options.node));
  auto camera = std::make_unique<EmulatedV4l2Camera>(options, frame_bgr, root_ + "/dev/" + options.node);
  GError* error = nullptr;
  if (!umockdev_testbed_attach_ioctl(testbed_, camera->DevicePath().c_str(), camera->handler(), &error)) {
    Status status =
        InternalError("umockdev: cannot attach to " + camera->DevicePath() + ": " + (error ? error->message : "?"));
    if (error != nullptr) g_error_free(error);
    return status;
  }
  cameras_.push_back(std::move(camera));
  return cameras_.back().get();
}

int RunTestsUnderUmockdev(int argc, char** argv) {
  if (!PreloadIsLoaded() && std::getenv("PX_UMOCKDEV_REEXEC") == nullptr) {
    std::string preload = PX_UMOCKDEV_PRELOAD;
    if (const char* existing = std::getenv("LD_PRELOAD"); existing != nullptr && *existing != '\0') {
      preload += std::string(":") + existing;
    }
    setenv("LD_PRELOAD", preload.c_str(), 1);
    setenv("PX_UMOCKDEV_REEXEC", "1", 1);  // once: if the preload does not take, tests skip with the reason
    execv("/proc/self/exe", argv);
    std::perror("re-exec under umockdev");
  }
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}

}  // namespace px::testing
