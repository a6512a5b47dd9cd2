#include "tests/drivers/ptp_responder.h"

#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <thread>

#include "drivers/ptp/ptp_codes.h"
#include "sim/synthetic/data_paths.h"
#include "sim/synthetic/synthetic_source.h"

namespace px::ptp::testing {
namespace {

using std::chrono::milliseconds;
using std::chrono::steady_clock;

// The responder's own little-endian writer (independent of drivers/ptp/ptp_bytes.h).
struct Le {
  std::vector<uint8_t> b;
  void u8(uint8_t v) { b.push_back(v); }
  void u16(uint16_t v) {
    u8(v & 0xff);
    u8(v >> 8);
  }
  void u32(uint32_t v) {
    u16(v & 0xffff);
    u16(v >> 16);
  }
  void str(const std::string& s) {
    if (s.empty()) {
      u8(0);
      return;
    }
    u8(static_cast<uint8_t>(s.size() + 1));
    for (char c : s) u16(static_cast<uint8_t>(c));
    u16(0);
  }
  void a16(const std::vector<uint16_t>& v) {
    u32(static_cast<uint32_t>(v.size()));
    for (auto x : v) u16(x);
  }
};

uint32_t Get32(const uint8_t* p) { return p[0] | (p[1] << 8) | (p[2] << 16) | (static_cast<uint32_t>(p[3]) << 24); }
uint16_t Get16(const uint8_t* p) { return static_cast<uint16_t>(p[0] | (p[1] << 8)); }

std::vector<uint8_t> MakeContainer(uint16_t type,
                                   uint16_t code,
                                   uint32_t transaction,
                                   const std::vector<uint32_t>& params,
                                   const std::vector<uint8_t>* payload) {
  Le out;
  const size_t length = 12 + 4 * params.size() + (payload ? payload->size() : 0);
  out.u32(static_cast<uint32_t>(length));
  out.u16(type);
  out.u16(code);
  out.u32(transaction);
  for (uint32_t p : params) out.u32(p);
  if (payload) out.b.insert(out.b.end(), payload->begin(), payload->end());
  return std::move(out.b);
}

}  // namespace

PtpResponder::PtpResponder(ResponderOptions options)
    : options_(std::move(options)), busy_left_(options_.busy_replies) {}

std::string PtpResponder::DeviceName() const {
  char text[48];
  std::snprintf(text, sizeof(text), "sim-ptp (%04x:%04x)", options_.vendor_id, options_.product_id);
  return text;
}

bool PtpResponder::unplugged() const {
  std::lock_guard lock(mutex_);
  return unplugged_;
}

void PtpResponder::Unplug() {
  std::lock_guard lock(mutex_);
  unplugged_ = true;
  activity_.notify_all();
}

PtpResponder::Stats PtpResponder::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

void PtpResponder::QueueBulkIn(std::vector<uint8_t> container) {
  const bool whole_packets = container.size() % options_.max_packet == 0;
  bulk_in_.push_back(std::move(container));
  // A transfer that ends on a packet boundary needs a zero-length packet to end it.
  if (whole_packets) bulk_in_.emplace_back();
  activity_.notify_all();
}

void PtpResponder::Answer(uint16_t code,
                          uint32_t transaction,
                          const std::vector<uint8_t>* data,
                          uint16_t response,
                          std::vector<uint32_t> response_params) {
  if (data) QueueBulkIn(MakeContainer(2, code, transaction, {}, data));
  QueueBulkIn(MakeContainer(3, response, transaction, response_params, nullptr));
}

bool PtpResponder::HandleBulkOut(std::span<const uint8_t> bytes) {
  std::lock_guard lock(mutex_);
  if (unplugged_) return false;
  if (bytes.size() < 12 || Get32(bytes.data()) != bytes.size() || Get16(bytes.data() + 4) != 1 ||
      (bytes.size() - 12) % 4 != 0 || bytes.size() > 32) {
    // Not a command container: a real camera stalls or answers GeneralError.
    QueueBulkIn(MakeContainer(3, rc::kGeneralError, 0, {}, nullptr));
    return true;
  }
  const uint16_t code = Get16(bytes.data() + 6);
  const uint32_t transaction = Get32(bytes.data() + 8);
  std::vector<uint32_t> params;
  for (size_t at = 12; at < bytes.size(); at += 4) params.push_back(Get32(bytes.data() + at));
  stats_.operations.push_back(code);
  stats_.transaction_ids.push_back(transaction);
  Handle(code, transaction, params);
  return true;
}

void PtpResponder::Handle(uint16_t code, uint32_t transaction, const std::vector<uint32_t>& params) {
  if (options_.fail_operation == code) {
    Answer(code, transaction, nullptr, options_.fail_response);
    return;
  }
  if (code == op::kGetDeviceInfo) {
    const auto info = DeviceInfoDataset();
    Answer(code, transaction, &info, rc::kOk);
    return;
  }
  if (code == op::kOpenSession) {
    if (session_open_) {
      Answer(code, transaction, nullptr, rc::kSessionAlreadyOpen, {1});
      return;
    }
    if (params.empty() || params[0] == 0) {
      Answer(code, transaction, nullptr, rc::kInvalidParameter);
      return;
    }
    session_open_ = true;
    ++stats_.sessions_opened;
    Answer(code, transaction, nullptr, rc::kOk);
    return;
  }
  if (!session_open_) {
    Answer(code, transaction, nullptr, rc::kSessionNotOpen);
    return;
  }
  switch (code) {
    case op::kCloseSession:
      session_open_ = false;
      ++stats_.sessions_closed;
      Answer(code, transaction, nullptr, rc::kOk);
      return;
    case op::kInitiateCapture: {
      if (busy_left_ > 0) {
        --busy_left_;
        ++stats_.busy_answers;
        Answer(code, transaction, nullptr, rc::kDeviceBusy);
        return;
      }
      if (options_.unplug_after_objects >= 0 && stats_.objects_sent >= options_.unplug_after_objects) {
        // The cable comes out as the shutter fires: no response, the device is gone.
        unplugged_ = true;
        activity_.notify_all();
        return;
      }
      if (options_.jpegs.empty()) {
        Answer(code, transaction, nullptr, rc::kStoreNotAvailable);
        return;
      }
      const uint32_t handle = next_handle_++;
      char name[32];
      std::snprintf(name, sizeof(name), "IMG_%04u.JPG", handle & 0xffff);
      objects_[handle] = Object{options_.jpegs[next_jpeg_++ % options_.jpegs.size()], name};
      ++stats_.captures;
      Answer(code, transaction, nullptr, rc::kOk);
      if (!options_.never_send_event) {
        const auto when = steady_clock::now() + options_.event_delay;
        events_.emplace_back(when, MakeContainer(4, ev::kObjectAdded, transaction, {handle}, nullptr));
        if (options_.capture_complete_event) {
          events_.emplace_back(when, MakeContainer(4, ev::kCaptureComplete, transaction, {transaction}, nullptr));
        }
      }
      return;
    }
    case op::kGetObjectInfo:
    case op::kGetObject:
    case op::kDeleteObject: {
      auto found = params.empty() ? objects_.end() : objects_.find(params[0]);
      if (found == objects_.end()) {
        Answer(code, transaction, nullptr, rc::kInvalidObjectHandle);
        return;
      }
      if (code == op::kGetObjectInfo) {
        const auto info = ObjectInfoDataset(found->first, found->second);
        Answer(code, transaction, &info, rc::kOk);
      } else if (code == op::kGetObject) {
        ++stats_.objects_sent;
        Answer(code, transaction, &found->second.bytes, rc::kOk);
      } else {
        objects_.erase(found);
        ++stats_.objects_deleted;
        Answer(code, transaction, nullptr, rc::kOk);
      }
      return;
    }
    case op::kGetDevicePropValue: {
      if (!params.empty() && params[0] == prop::kImageSize && options_.image_width > 0) {
        Le value;
        value.str(std::to_string(options_.image_width) + "x" + std::to_string(options_.image_height));
        Answer(code, transaction, &value.b, rc::kOk);
      } else {
        Answer(code, transaction, nullptr, rc::kDevicePropNotSupported);
      }
      return;
    }
    default:
      Answer(code, transaction, nullptr, rc::kOperationNotSupported);
  }
}

std::optional<std::vector<uint8_t>> PtpResponder::TakeBulkIn(size_t max_bytes) {
  std::lock_guard lock(mutex_);
  if (unplugged_ || bulk_in_.empty()) return std::nullopt;
  std::vector<uint8_t>& front = bulk_in_.front();
  ++stats_.bulk_in_transfers;
  if (front.empty()) {
    ++stats_.zero_length_packets;
    bulk_in_.pop_front();
    return std::vector<uint8_t>();
  }
  // A transfer carries whole packets and ends with the container (a short packet).
  const size_t count = std::min(max_bytes / options_.max_packet * options_.max_packet, front.size() - bulk_in_offset_);
  std::vector<uint8_t> out(front.begin() + bulk_in_offset_, front.begin() + bulk_in_offset_ + count);
  bulk_in_offset_ += count;
  if (bulk_in_offset_ == front.size()) {
    bulk_in_.pop_front();
    bulk_in_offset_ = 0;
    // The zero-length packet ends this same transfer when the host asked for more.
    if (count < max_bytes && !bulk_in_.empty() && bulk_in_.front().empty()) {
      ++stats_.zero_length_packets;
      bulk_in_.pop_front();
    }
  }
  return out;
}

std::optional<std::vector<uint8_t>> PtpResponder::TakeEvent() {
  std::lock_guard lock(mutex_);
  if (unplugged_ || events_.empty() || events_.front().first > steady_clock::now()) return std::nullopt;
  auto event = std::move(events_.front().second);
  events_.pop_front();
  return event;
}

void PtpResponder::WaitForActivity(milliseconds timeout) {
  std::unique_lock lock(mutex_);
  const auto until = steady_clock::now() + timeout;
  activity_.wait_until(lock, until, [&] {
    return unplugged_ || !bulk_in_.empty() || (!events_.empty() && events_.front().first <= steady_clock::now());
  });
}

std::vector<uint8_t> PtpResponder::DeviceInfoDataset() const {
  Le out;
  out.u16(100);  // StandardVersion 1.00
  out.u32(0);    // VendorExtensionID
  out.u16(0);
  out.str("");
  out.u16(0);  // FunctionalMode
  out.a16({op::kGetDeviceInfo,
           op::kOpenSession,
           op::kCloseSession,
           op::kGetObjectInfo,
           op::kGetObject,
           op::kDeleteObject,
           op::kInitiateCapture,
           op::kGetDevicePropValue});
  std::vector<uint16_t> events = {ev::kObjectAdded};
  if (options_.capture_complete_event) events.push_back(ev::kCaptureComplete);
  out.a16(events);
  std::vector<uint16_t> props;
  if (options_.image_width > 0) props.push_back(prop::kImageSize);
  out.a16(props);
  out.a16({fmt::kExifJpeg});
  out.a16({fmt::kExifJpeg});
  out.str(options_.manufacturer);
  out.str(options_.model);
  out.str("1.0");
  out.str("SIM0001");
  return std::move(out.b);
}

std::vector<uint8_t> PtpResponder::ObjectInfoDataset(uint32_t handle, const Object& object) const {
  Le out;
  out.u32(0x00010001);  // StorageID
  out.u16(fmt::kExifJpeg);
  out.u16(0);
  out.u32(static_cast<uint32_t>(object.bytes.size()));
  out.u16(0);  // no thumbnail
  out.u32(0);
  out.u32(0);
  out.u32(0);
  out.u32(static_cast<uint32_t>(options_.image_width));
  out.u32(static_cast<uint32_t>(options_.image_height));
  out.u32(24);
  out.u32(0);  // ParentObject
  out.u16(0);
  out.u32(0);
  out.u32(handle & 0xffff);  // SequenceNumber
  out.str(object.filename);
  out.str("20260101T120000");
  out.str("20260101T120000");
  out.str("");
  return std::move(out.b);
}

namespace {

class ResponderTransport final : public PtpTransport {
 public:
  explicit ResponderTransport(std::shared_ptr<PtpResponder> responder) : responder_(std::move(responder)) {}

  std::string DeviceName() const override { return responder_->DeviceName(); }
  size_t MaxPacketBytes() const override { return responder_->max_packet(); }

  Status BulkOut(std::span<const uint8_t> bytes, milliseconds) override {
    if (!responder_->HandleBulkOut(bytes)) return Gone("bulk-out");
    return OkStatus();
  }

  StatusOr<std::vector<uint8_t>> BulkIn(size_t max_bytes, milliseconds timeout) override {
    return Wait(timeout, "bulk-in", [&] { return responder_->TakeBulkIn(max_bytes); });
  }

  StatusOr<std::vector<uint8_t>> InterruptIn(size_t, milliseconds timeout) override {
    return Wait(timeout, "interrupt-in", [&] { return responder_->TakeEvent(); });
  }

 private:
  Status Gone(const std::string& pipe) const {
    return UnavailableError(DeviceName() + " " + pipe + ": the camera has been disconnected (LIBUSB_ERROR_NO_DEVICE)");
  }

  template <typename Take>
  StatusOr<std::vector<uint8_t>> Wait(milliseconds timeout, const std::string& pipe, Take take) {
    const auto until = steady_clock::now() + timeout;
    while (true) {
      if (responder_->unplugged()) return Gone(pipe);
      if (auto bytes = take()) return *std::move(bytes);
      const auto left = std::chrono::duration_cast<milliseconds>(until - steady_clock::now());
      if (left.count() <= 0) return DeadlineExceededError(DeviceName() + " " + pipe + ": timed out");
      responder_->WaitForActivity(std::min(left, milliseconds(20)));
    }
  }

  std::shared_ptr<PtpResponder> responder_;
};

}  // namespace

std::unique_ptr<PtpTransport> MakeResponderTransport(std::shared_ptr<PtpResponder> responder) {
  return std::make_unique<ResponderTransport>(std::move(responder));
}

StatusOr<HandHeldShots> RenderHandHeldShots(int width, int height) {
  static std::mutex mutex;
  static std::map<std::pair<int, int>, HandHeldShots> cache;
  std::lock_guard lock(mutex);
  if (auto found = cache.find({width, height}); found != cache.end()) return found->second;
  SyntheticSourceOptions options;
  options.camera = SimCameraSpec::Pop9();
  options.camera.focal_px *= static_cast<double>(width) / options.camera.tile_width;
  options.camera.tile_width = width;
  options.camera.tile_height = height;
  options.camera.gap_px = 4;
  options.camera.supersampling = 1;
  options.scene_file = sim::ScenesDir() / "still_life.json";
  PX_ASSIGN_OR_RETURN(auto source, MakeSyntheticSource(options));
  SourceConfig granted;
  PX_ASSIGN_OR_RETURN(ConfigureResult configured, source->Configure(SourceConfig{PixelFormat::kRgb888}, &granted));
  (void)configured;
  PX_ASSIGN_OR_RETURN(FrameSet frames, source->Next(milliseconds(60000)));
  (void)frames;
  PX_ASSIGN_OR_RETURN(sim::GroundTruth truth, LastGroundTruth(*source));
  HandHeldShots shots;
  for (const auto& view : truth.views) {
    std::vector<uint8_t> jpeg;
    if (!cv::imencode(".jpg", view.bgr, jpeg, {cv::IMWRITE_JPEG_QUALITY, 95})) {
      return InternalError("cv::imencode(.jpg) failed for view " + std::to_string(shots.jpegs.size()));
    }
    shots.jpegs.push_back(std::move(jpeg));
    shots.bgr.push_back(view.bgr.clone());
  }
  cache[{width, height}] = shots;
  return shots;
}

}  // namespace px::ptp::testing
