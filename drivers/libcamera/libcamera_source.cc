#include "drivers/libcamera/libcamera_source.h"

#include <libcamera/camera.h>
#include <libcamera/camera_manager.h>
#include <libcamera/formats.h>
#include <libcamera/framebuffer.h>
#include <libcamera/framebuffer_allocator.h>
#include <libcamera/request.h>
#include <libcamera/stream.h>

#include <algorithm>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <map>
#include <mutex>

#include "drivers/libcamera/camera_manager_lease.h"
#include "drivers/libcamera/libcamera_formats.h"
#include "drivers/libcamera/mapped_plane.h"
#include "drivers/libcamera/plane_copy.h"
#include "pipeline/core/log.h"
#include "pipeline/core/rig_calibration_json.h"
#include "pipeline/io/durable_file.h"

namespace px::libcamera_driver {

// The table in libcamera_formats.h must agree with the libcamera we compile against.
static_assert(libcamera::formats::RGB888.fourcc() == kFourccRgb888);
static_assert(libcamera::formats::BGR888.fourcc() == kFourccBgr888);
static_assert(libcamera::formats::YUYV.fourcc() == kFourccYuyv);
static_assert(libcamera::formats::NV12.fourcc() == kFourccNv12);
static_assert(libcamera::formats::SRGGB8.fourcc() == kFourccSrggb8);
static_assert(libcamera::formats::R8.fourcc() == kFourccR8);

namespace {

std::string Errno(int negative_errno) { return std::strerror(-negative_errno); }

class LibcameraSource final : public FrameSource {
 public:
  LibcameraSource(LibcameraOptions options, std::optional<RigCalibration> rig)
      : options_(std::move(options)), rig_(std::move(rig)) {}
  ~LibcameraSource() override { Stop(); }

  std::string_view Name() const override { return "libcamera"; }

  SourceDescription Describe() const override {
    SourceDescription description;
    description.model = "libcamera:" + (camera_ ? camera_->id() : DisplayId());
    description.kind = FrameSetKind::kLatticeFrame;
    description.rig = rig_;
    return description;
  }

  StatusOr<ConfigureResult> Configure(const SourceConfig& wanted, SourceConfig* granted) override;
  StatusOr<FrameSet> Next(std::chrono::milliseconds timeout) override;
  void Stop() override;

 private:
  std::string DisplayId() const { return options_.camera_id.empty() ? "(first camera)" : options_.camera_id; }
  std::string What() const { return "libcamera camera '" + (camera_ ? camera_->id() : DisplayId()) + "'"; }
  Status AcquireCamera();
  Status PrepareBuffers();
  void StopStreaming();
  void ReleaseCamera();
  Frame ToFrame(libcamera::Request* request);

  // libcamera's thread calls these.
  void OnRequestCompleted(libcamera::Request* request);
  void OnCameraRemoved(std::shared_ptr<libcamera::Camera> camera);
  void OnDisconnected();

  LibcameraOptions options_;
  std::optional<RigCalibration> rig_;
  std::shared_ptr<libcamera::CameraManager> manager_;
  std::shared_ptr<libcamera::Camera> camera_;
  std::unique_ptr<libcamera::CameraConfiguration> config_;
  libcamera::Stream* stream_ = nullptr;
  std::unique_ptr<libcamera::FrameBufferAllocator> allocator_;
  std::vector<std::unique_ptr<libcamera::Request>> requests_;
  std::map<const libcamera::FrameBuffer*, std::vector<MappedPlane>> mappings_;
  bool started_ = false;
  bool configured_ = false;
  SourceConfig granted_;
  size_t stride_ = 0;
  size_t next_request_ = 0;
  uint64_t capture_id_ = 0;

  std::mutex mutex_;
  std::condition_variable completed_changed_;
  std::deque<libcamera::Request*> completed_;  // guarded by mutex_
  bool removed_ = false;                       // guarded by mutex_
};

Status LibcameraSource::AcquireCamera() {
  if (camera_) return OkStatus();
  PX_ASSIGN_OR_RETURN(manager_, LeaseCameraManager());
  const std::vector<std::shared_ptr<libcamera::Camera>> cameras = manager_->cameras();
  if (cameras.empty()) {
    manager_.reset();
    return UnavailableError("libcamera " + libcamera::CameraManager::version() + " lists no cameras" +
                            (options_.camera_id.empty() ? "" : " (wanted '" + options_.camera_id + "')"));
  }
  std::shared_ptr<libcamera::Camera> camera =
      options_.camera_id.empty() ? cameras.front() : manager_->get(options_.camera_id);
  if (!camera) {
    std::string ids;
    for (const auto& c : cameras) ids += (ids.empty() ? "" : ", ") + c->id();
    manager_.reset();
    return UnavailableError("libcamera camera '" + options_.camera_id + "' not found (libcamera lists: " + ids + ")");
  }
  if (int ret = camera->acquire(); ret != 0) {
    manager_.reset();
    return UnavailableError("libcamera camera '" + camera->id() + "': acquire failed: " + Errno(ret) +
                            (ret == -EBUSY ? " (another process uses it)" : ""));
  }
  camera_ = std::move(camera);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    removed_ = false;
    completed_.clear();
  }
  camera_->requestCompleted.connect(this, &LibcameraSource::OnRequestCompleted);
  camera_->disconnected.connect(this, &LibcameraSource::OnDisconnected);
  manager_->cameraRemoved.connect(this, &LibcameraSource::OnCameraRemoved);
  Logger("libcamera")->info("acquired camera '{}' (libcamera {})", camera_->id(), libcamera::CameraManager::version());
  return OkStatus();
}

StatusOr<ConfigureResult> LibcameraSource::Configure(const SourceConfig& wanted, SourceConfig* granted) {
  StopStreaming();
  PX_RETURN_IF_ERROR(AcquireCamera());
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (removed_) return UnavailableError(What() + " was removed");
  }
  config_ = camera_->generateConfiguration({libcamera::StreamRole::StillCapture});
  if (!config_ || config_->empty()) return UnavailableError(What() + ": offers no still-capture stream");
  libcamera::StreamConfiguration& stream_config = config_->at(0);
  const bool sized = wanted.width > 0 && wanted.height > 0;
  if (sized) stream_config.size = libcamera::Size(wanted.width, wanted.height);
  const libcamera::Size asked_size = stream_config.size;
  stream_config.pixelFormat = libcamera::PixelFormat(FourccFromPxFormat(wanted.pixel_format));

  libcamera::CameraConfiguration::Status validated = config_->validate();
  if (validated == libcamera::CameraConfiguration::Invalid) {
    return InvalidArgumentError(What() + ": cannot capture " + DescribeConfig(wanted) +
                                " (libcamera's validate() says Invalid)");
  }
  // validate() may move to a format we cannot convert (MJPEG, 10-bit Bayer): try ours in turn.
  if (!PxFormatFromFourcc(stream_config.pixelFormat.fourcc())) {
    const uint32_t offered = stream_config.pixelFormat.fourcc();
    for (const FormatMapping& mapping : SupportedFormats()) {
      stream_config.pixelFormat = libcamera::PixelFormat(mapping.fourcc);
      stream_config.size = asked_size;
      validated = config_->validate();
      if (validated != libcamera::CameraConfiguration::Invalid &&
          PxFormatFromFourcc(stream_config.pixelFormat.fourcc())) {
        break;
      }
    }
    if (validated == libcamera::CameraConfiguration::Invalid ||
        !PxFormatFromFourcc(stream_config.pixelFormat.fourcc())) {
      return InvalidArgumentError(What() + ": offers " + DescribeFourcc(offered) +
                                  ", none of RGB888, BGR888, YUYV, NV12, SRGGB8, R8");
    }
    validated = libcamera::CameraConfiguration::Adjusted;
  }

  SourceConfig result;
  result.pixel_format = *PxFormatFromFourcc(stream_config.pixelFormat.fourcc());
  result.width = static_cast<int>(stream_config.size.width);
  result.height = static_cast<int>(stream_config.size.height);
  result.shots = 1;
  const bool adjusted = validated == libcamera::CameraConfiguration::Adjusted ||
                        result.pixel_format != wanted.pixel_format || wanted.shots != 1 ||
                        (sized && (result.width != wanted.width || result.height != wanted.height));

  if (int ret = camera_->configure(config_.get()); ret != 0) {
    return InvalidArgumentError(What() + ": configure " + stream_config.toString() + " failed: " + Errno(ret));
  }
  stream_ = stream_config.stream();
  stride_ = stream_config.stride;
  granted_ = result;
  PX_RETURN_IF_ERROR(PrepareBuffers());
  if (int ret = camera_->start(); ret != 0) return UnavailableError(What() + ": start failed: " + Errno(ret));
  started_ = true;
  configured_ = true;
  *granted = result;
  Logger("libcamera")
      ->info(
          "{}: configured {} (stride {}, {} buffer(s))", What(), stream_config.toString(), stride_, requests_.size());
  return adjusted ? ConfigureResult::kAdjusted : ConfigureResult::kValid;
}

Status LibcameraSource::PrepareBuffers() {
  allocator_ = std::make_unique<libcamera::FrameBufferAllocator>(camera_);
  if (int ret = allocator_->allocate(stream_); ret < 0) {
    return UnavailableError(What() + ": buffer allocation failed: " + Errno(ret));
  }
  uint64_t cookie = 0;
  for (const std::unique_ptr<libcamera::FrameBuffer>& buffer : allocator_->buffers(stream_)) {
    std::vector<MappedPlane> planes;
    for (const libcamera::FrameBuffer::Plane& plane : buffer->planes()) {
      const size_t offset = plane.offset == libcamera::FrameBuffer::Plane::kInvalidOffset ? 0 : plane.offset;
      auto mapped = MappedPlane::Map(plane.fd.get(), offset, plane.length);
      if (!mapped.ok()) return mapped.status().WithContext(What());
      planes.push_back(std::move(mapped).value());
    }
    mappings_[buffer.get()] = std::move(planes);
    std::unique_ptr<libcamera::Request> request = camera_->createRequest(cookie++);
    if (!request) return UnavailableError(What() + ": createRequest failed");
    if (int ret = request->addBuffer(stream_, buffer.get()); ret != 0) {
      return UnavailableError(What() + ": addBuffer failed: " + Errno(ret));
    }
    requests_.push_back(std::move(request));
  }
  if (requests_.empty()) return UnavailableError(What() + ": no buffers allocated");
  return OkStatus();
}

StatusOr<FrameSet> LibcameraSource::Next(std::chrono::milliseconds timeout) {
  if (!configured_) return FailedPreconditionError("libcamera source: Next() before Configure() or after Stop()");
  std::unique_lock<std::mutex> lock(mutex_);
  if (removed_) return UnavailableError(What() + " was removed");
  completed_.clear();
  libcamera::Request* request = requests_[next_request_++ % requests_.size()].get();
  request->reuse(libcamera::Request::ReuseBuffers);
  lock.unlock();
  if (int ret = camera_->queueRequest(request); ret != 0) {
    if (ret == -ENODEV) return UnavailableError(What() + " was removed");
    return UnavailableError(What() + ": queueRequest failed: " + Errno(ret));
  }
  lock.lock();
  const bool answered = completed_changed_.wait_for(lock, timeout, [&] { return removed_ || !completed_.empty(); });
  if (removed_) return UnavailableError(What() + " was removed");
  if (!answered) {
    lock.unlock();
    // Stopping cancels the request in flight; starting again leaves a clean camera for the next call.
    camera_->stop();
    const int ret = camera_->start();
    started_ = ret == 0;
    configured_ = started_;
    {
      std::lock_guard<std::mutex> relock(mutex_);
      completed_.clear();
    }
    return DeadlineExceededError(What() + ": no frame within " + std::to_string(timeout.count()) + " ms" +
                                 (started_ ? "" : "; restart failed: " + Errno(ret)));
  }
  libcamera::Request* done = completed_.front();
  completed_.pop_front();
  lock.unlock();

  FrameSet frames;
  frames.kind = FrameSetKind::kLatticeFrame;
  frames.capture_id = ++capture_id_;
  frames.frames.push_back(ToFrame(done));
  return frames;
}

Frame LibcameraSource::ToFrame(libcamera::Request* request) {
  Frame frame;
  frame.image.format = granted_.pixel_format;
  frame.image.width = granted_.width;
  frame.image.height = granted_.height;
  libcamera::FrameBuffer* buffer = request->findBuffer(stream_);
  if (request->status() == libcamera::Request::RequestCancelled || buffer == nullptr) {
    frame.status = FrameStatus::kDropped;
    frame.status_detail = What() + ": request cancelled";
    return frame;
  }
  const libcamera::FrameMetadata& metadata = buffer->metadata();
  frame.sequence = metadata.sequence;
  frame.timestamp_ns = static_cast<int64_t>(metadata.timestamp);
  if (metadata.status != libcamera::FrameMetadata::FrameSuccess) {
    frame.status =
        metadata.status == libcamera::FrameMetadata::FrameCancelled ? FrameStatus::kDropped : FrameStatus::kCorrupt;
    frame.status_detail =
        What() + ": frame " + std::to_string(metadata.sequence) +
        (metadata.status == libcamera::FrameMetadata::FrameCancelled ? " cancelled" : " has an error");
    return frame;
  }
  const std::vector<MappedPlane>& mapped = mappings_.at(buffer);
  std::vector<PlaneView> planes;
  for (size_t i = 0; i < mapped.size(); ++i) {
    size_t used = i < metadata.planes().size() ? metadata.planes()[i].bytesused : 0;
    if (used == 0 || used > mapped[i].length()) used = mapped[i].length();
    planes.push_back({mapped[i].data(), used, stride_});
  }
  auto image = CopyPlanes(granted_.pixel_format, granted_.width, granted_.height, planes);
  if (!image.ok()) {
    frame.status = FrameStatus::kCorrupt;
    frame.status_detail = What() + ": " + std::string(image.status().message());
    return frame;
  }
  frame.image = std::move(image).value();
  return frame;
}

void LibcameraSource::OnRequestCompleted(libcamera::Request* request) {
  std::lock_guard<std::mutex> lock(mutex_);
  completed_.push_back(request);
  completed_changed_.notify_all();
}

void LibcameraSource::OnCameraRemoved(std::shared_ptr<libcamera::Camera> camera) {
  if (camera != camera_) return;
  OnDisconnected();
}

void LibcameraSource::OnDisconnected() {
  std::lock_guard<std::mutex> lock(mutex_);
  removed_ = true;
  completed_changed_.notify_all();
}

void LibcameraSource::StopStreaming() {
  if (started_ && camera_) camera_->stop();
  started_ = false;
  configured_ = false;
  requests_.clear();  // requests refer to the buffers: go first
  mappings_.clear();
  allocator_.reset();
  config_.reset();
  stream_ = nullptr;
  std::lock_guard<std::mutex> lock(mutex_);
  completed_.clear();
}

void LibcameraSource::ReleaseCamera() {
  if (camera_) {
    camera_->requestCompleted.disconnect(this);
    camera_->disconnected.disconnect(this);
    if (manager_) manager_->cameraRemoved.disconnect(this);
    camera_->release();
    Logger("libcamera")->info("released camera '{}'", camera_->id());
    camera_.reset();
  }
  manager_.reset();  // the last lease stops the camera manager
}

void LibcameraSource::Stop() {
  StopStreaming();
  ReleaseCamera();
}

}  // namespace

StatusOr<std::unique_ptr<FrameSource>> OpenLibcameraSource(const LibcameraOptions& options) {
  std::optional<RigCalibration> rig;
  if (!options.rig_calibration.empty()) {
    auto text = ReadFileToString(options.rig_calibration);
    if (!text.ok()) return text.status().WithContext("rig calibration");
    auto parsed = RigCalibrationFromJsonText(*text);
    if (!parsed.ok()) return parsed.status().WithContext(options.rig_calibration.string());
    rig = std::move(parsed).value();
  }
  return std::unique_ptr<FrameSource>(new LibcameraSource(options, std::move(rig)));
}

StatusOr<LibcameraInventory> ListLibcameraCameras() {
  PX_ASSIGN_OR_RETURN(std::shared_ptr<libcamera::CameraManager> manager, LeaseCameraManager());
  LibcameraInventory inventory;
  inventory.version = libcamera::CameraManager::version();
  for (const auto& camera : manager->cameras()) inventory.camera_ids.push_back(camera->id());
  return inventory;
}

}  // namespace px::libcamera_driver
