#include "drivers/ptp/ptp_source.h"

#include <algorithm>
#include <cstdio>
#include <opencv2/imgproc.hpp>
#include <optional>

#include "pipeline/core/log.h"
#include "pipeline/io/exif.h"
#include "pipeline/io/image_file.h"

namespace px {
namespace {

using std::chrono::milliseconds;
using std::chrono::steady_clock;
using namespace ptp;  // NOLINT: codes and the session

// "6000x4000" -> {6000, 4000}; anything else -> nullopt.
std::optional<std::pair<int, int>> ParseImageSize(const std::string& text) {
  int width = 0;
  int height = 0;
  char x = 0;
  if (std::sscanf(text.c_str(), "%d%c%d", &width, &x, &height) != 3 || (x != 'x' && x != 'X') || width <= 0 ||
      height <= 0) {
    return std::nullopt;
  }
  return std::make_pair(width, height);
}

class PtpSource final : public FrameSource {
 public:
  explicit PtpSource(PtpSourceOptions options) : options_(std::move(options)) {
    if (!options_.clock) {
      own_clock_ = std::make_unique<SteadyClock>();
      options_.clock = own_clock_.get();
    }
  }

  std::string_view Name() const override { return "ptp"; }

  SourceDescription Describe() const override {
    SourceDescription description;
    description.model =
        "ptp:" + (device_info_ ? device_info_->manufacturer + " " + device_info_->model + " (" + device_name_ + ")"
                               : options_.label);
    description.kind = FrameSetKind::kImageSet;
    description.rig = std::nullopt;  // hand-held: the poses are unknown until the pipeline solves them
    return description;
  }

  StatusOr<ConfigureResult> Configure(const SourceConfig& wanted, SourceConfig* granted) override {
    PX_RETURN_IF_ERROR(Connect());
    SourceConfig grant = wanted;
    if (grant.pixel_format != PixelFormat::kRgb888 && grant.pixel_format != PixelFormat::kBgr888) {
      grant.pixel_format = PixelFormat::kRgb888;
    }
    grant.shots = std::clamp(wanted.shots, kPtpMinShots, kPtpMaxShots);
    grant.width = native_width_;
    grant.height = native_height_;
    // Sizes the camera does not report are taken as they come (0 = any).
    if (native_width_ == 0) {
      grant.width = 0;
      grant.height = 0;
    }
    *granted = grant;
    granted_ = grant;
    configured_ = true;
    return grant == wanted ? ConfigureResult::kValid : ConfigureResult::kAdjusted;
  }

  StatusOr<FrameSet> Next(milliseconds timeout) override {
    if (!configured_) return FailedPreconditionError("ptp " + options_.label + ": Next() before Configure()");
    if (!session_ || session_->device_gone()) {
      return UnavailableError("ptp camera " + device_name_ +
                              " has been disconnected; plug it back in and configure the source again");
    }
    const auto deadline = steady_clock::now() + timeout;
    FrameSet frames;
    frames.kind = FrameSetKind::kImageSet;
    frames.capture_id = ++capture_id_;
    Status stopped;
    int taken = 0;
    for (int shot = 0; shot < granted_.shots; ++shot) {
      Frame frame;
      frame.sequence = ++sequence_;
      if (stopped.ok()) {
        Status shot_status = TakeShot(shot, deadline, &frame);
        if (shot_status.ok()) {
          ++taken;
        } else {
          stopped = shot_status;
        }
      }
      if (!stopped.ok() && frame.image.bytes.empty()) {
        frame.status = FrameStatus::kDropped;
        frame.timestamp_ns = options_.clock->NowNs();
        frame.status_detail = "shot " + std::to_string(shot + 1) + " of " + std::to_string(granted_.shots) +
                              " not taken: " + stopped.ToString();
      }
      frames.frames.push_back(std::move(frame));
    }
    if (stopped.ok()) return frames;
    if (taken == 0) return stopped;
    Logger("ptp")->warn("{}: {} of {} shots taken, then {}", device_name_, taken, granted_.shots, stopped.ToString());
    return frames;
  }

  void Stop() override {
    configured_ = false;
    if (session_ && session_->is_open() && !session_->device_gone()) {
      if (Status closed = session_->CloseSession(); !closed.ok()) {
        Logger("ptp")->warn("{}: {}", device_name_, closed.ToString());
      }
    }
    session_.reset();
  }

 private:
  Status Connect() {
    if (session_ && !session_->device_gone()) return OkStatus();
    session_.reset();
    if (!options_.open_transport) return FailedPreconditionError("ptp " + options_.label + ": no transport");
    PX_ASSIGN_OR_RETURN(std::unique_ptr<PtpTransport> transport, options_.open_transport());
    device_name_ = transport->DeviceName();
    auto session = std::make_unique<PtpSession>(std::move(transport), options_.session);
    PX_ASSIGN_OR_RETURN(DeviceInfo info, session->GetDeviceInfo());
    for (uint16_t needed : {op::kOpenSession, op::kInitiateCapture, op::kGetObjectInfo, op::kGetObject}) {
      if (!info.SupportsOperation(needed)) {
        return UnimplementedError("ptp camera " + info.manufacturer + " " + info.model + " (" + device_name_ +
                                  ") does not support " + OperationName(needed) + ", which remote capture needs");
      }
    }
    PX_RETURN_IF_ERROR(session->OpenSession());
    native_width_ = 0;
    native_height_ = 0;
    if (info.SupportsProperty(prop::kImageSize)) {
      auto size_text = session->GetDevicePropString(prop::kImageSize);
      auto size = size_text.ok() ? ParseImageSize(*size_text) : std::nullopt;
      if (size) {
        native_width_ = size->first;
        native_height_ = size->second;
      } else {
        Logger("ptp")->warn("{}: ImageSize unreadable ({}); frames take whatever size the camera sends",
                            device_name_,
                            size_text.ok() ? "'" + *size_text + "'" : size_text.status().ToString());
      }
    }
    supports_capture_complete_ =
        std::find(info.events_supported.begin(), info.events_supported.end(), ev::kCaptureComplete) !=
        info.events_supported.end();
    Logger("ptp")->info("{}: {} {} connected, image size {}x{}",
                        device_name_,
                        info.manufacturer,
                        info.model,
                        native_width_,
                        native_height_);
    device_info_ = std::move(info);
    session_ = std::move(session);
    return OkStatus();
  }

  // One capture into *frame. A download or decode problem marks the frame (and returns OK);
  // a failure that stops the capture (camera gone, no event, refused operation) returns it.
  Status TakeShot(int shot, steady_clock::time_point deadline, Frame* frame) {
    const std::string what = "shot " + std::to_string(shot + 1) + " of " + std::to_string(granted_.shots);
    const auto shot_deadline = std::min(deadline, steady_clock::now() + options_.shot_timeout);
    PX_ASSIGN_OR_RETURN(uint32_t transaction, session_->InitiateCapture());
    auto added = session_->WaitForEvent(ev::kObjectAdded, shot_deadline);
    if (!added.ok()) return added.status().WithContext(what);
    frame->timestamp_ns = options_.clock->NowNs();
    if (added->params.empty()) return DataLossError(what + ": ObjectAdded event without an object handle");
    const uint32_t handle = added->params[0];
    if (supports_capture_complete_) {
      auto complete = session_->WaitForEvent(ev::kCaptureComplete, shot_deadline);
      if (!complete.ok() && complete.status().code() != StatusCode::kDeadlineExceeded) {
        return complete.status().WithContext(what);
      }
      if (complete.ok() && !complete->params.empty() && complete->params[0] != transaction) {
        Logger("ptp")->debug(
            "{}: CaptureComplete for transaction {}, want {}", device_name_, complete->params[0], transaction);
      }
    }
    PX_ASSIGN_OR_RETURN(ObjectInfo info, session_->GetObjectInfo(handle));
    PX_ASSIGN_OR_RETURN(std::vector<uint8_t> jpeg, session_->GetObject(handle));
    if (options_.delete_after_download) {
      if (Status deleted = session_->DeleteObject(handle); !deleted.ok()) {
        if (session_->device_gone()) return deleted;
        Logger("ptp")->warn("{}: {}", device_name_, deleted.ToString());
      }
    }
    const std::string object =
        "object " + std::to_string(handle) + " (" + info.filename + ", " + std::to_string(jpeg.size()) + " bytes)";
    if (info.object_compressed_size != 0 && info.object_compressed_size != jpeg.size()) {
      frame->status = FrameStatus::kCorrupt;
      frame->status_detail =
          what + ": " + object + ": ObjectInfo announced " + std::to_string(info.object_compressed_size) + " bytes";
      return OkStatus();
    }
    // The camera's bytes are not trusted: the size their header claims is checked before decoding.
    StatusOr<cv::Mat> decoded = DecodeImageBytes(jpeg, object);
    if (!decoded.ok()) {
      frame->status = FrameStatus::kCorrupt;
      frame->status_detail = what + ": " + object + ": not a decodable image (format " + Hex16(info.object_format) +
                             "): " + decoded.status().message();
      return OkStatus();
    }
    cv::Mat bgr = std::move(decoded).value();
    // The lens's focal length from the JPEG's EXIF, for structure from motion (imdecode has
    // turned the image upright, which FocalPx expects). A missing or unreadable EXIF leaves it unknown.
    if (StatusOr<ExifInfo> exif = ParseJpegExif(jpeg); exif.ok()) {
      frame->focal_length_px = exif->FocalPx(bgr.cols, bgr.rows, &frame->focal_length_source);
    } else {
      Logger("ptp")->warn("{}: {}: {}: {}; its focal length will be self-calibrated",
                          device_name_,
                          what,
                          object,
                          exif.status().ToString());
    }
    if (granted_.pixel_format == PixelFormat::kRgb888) cv::cvtColor(bgr, bgr, cv::COLOR_BGR2RGB);
    frame->image.format = granted_.pixel_format;
    frame->image.width = bgr.cols;
    frame->image.height = bgr.rows;
    frame->image.bytes.assign(bgr.data, bgr.data + bgr.total() * bgr.elemSize());
    // The recording keeps the camera's own file rather than re-encoding its pixels.
    if (granted_.pixel_format == PixelFormat::kRgb888) frame->jpeg = jpeg;
    if ((granted_.width != 0 && bgr.cols != granted_.width) || (granted_.height != 0 && bgr.rows != granted_.height)) {
      frame->status = FrameStatus::kWrongFormat;
      frame->status_detail = what + ": " + object + ": " + std::to_string(bgr.cols) + "x" + std::to_string(bgr.rows) +
                             ", the camera's ImageSize says " + std::to_string(granted_.width) + "x" +
                             std::to_string(granted_.height);
    }
    Logger("ptp")->debug("{}: {}: {} {}x{}", device_name_, what, object, bgr.cols, bgr.rows);
    return OkStatus();
  }

  PtpSourceOptions options_;
  std::unique_ptr<SteadyClock> own_clock_;
  std::unique_ptr<PtpSession> session_;
  std::optional<DeviceInfo> device_info_;
  std::string device_name_ = "(not connected)";
  int native_width_ = 0;
  int native_height_ = 0;
  bool supports_capture_complete_ = false;
  bool configured_ = false;
  SourceConfig granted_;
  uint64_t capture_id_ = 0;
  uint64_t sequence_ = 0;
};

}  // namespace

Status PtpSourceOptions::Validate() const {
  if (shot_timeout.count() <= 0 || shot_timeout.count() > 600000) {
    return InvalidArgumentError("ptp.shot_timeout: " + std::to_string(shot_timeout.count()) +
                                " ms is not in (0, 600000]");
  }
  if (!open_transport) return InvalidArgumentError("ptp.open_transport: not set");
  return session.Validate();
}

StatusOr<std::unique_ptr<FrameSource>> MakePtpSource(PtpSourceOptions options) {
  PX_RETURN_IF_ERROR(options.Validate());
  return std::unique_ptr<FrameSource>(std::make_unique<PtpSource>(std::move(options)));
}

}  // namespace px
