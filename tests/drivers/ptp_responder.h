// A simulated PTP camera for tests: the device side of PIMA 15740 over USB, speaking the
// protocol byte for byte. It parses command containers from the bulk-out pipe, answers with
// data and response containers on the bulk-in pipe (split into transfers as a USB device would,
// with a zero-length packet after a container that fills whole packets) and queues ObjectAdded
// and CaptureComplete events on the interrupt pipe after InitiateCapture. It encodes its
// datasets with its own little-endian writer, not the initiator's, so the two check each other.
//
// Faults: DeviceBusy answers, a camera that never sends the event, a camera unplugged after N
// objects, a chosen operation answered with a chosen response code.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <opencv2/core.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "drivers/ptp/ptp_transport.h"

namespace px::ptp::testing {

struct ResponderOptions {
  std::string manufacturer = "Parallax Sim";
  std::string model = "Handheld PTP";
  uint16_t vendor_id = 0x1d6b;  // for the device name, "sim-ptp (1d6b:0104)"
  uint16_t product_id = 0x0104;
  std::vector<std::vector<uint8_t>> jpegs;  // served in turn, one per capture (cycled)
  int image_width = 0;                      // reported ImageSize; 0 = do not support the property
  int image_height = 0;
  size_t max_packet = 512;  // bulk-in wMaxPacketSize
  bool capture_complete_event = true;
  std::chrono::milliseconds event_delay{0};  // between InitiateCapture's response and ObjectAdded

  // Faults.
  int busy_replies = 0;           // InitiateCapture answers DeviceBusy this many times first
  bool never_send_event = false;  // InitiateCapture succeeds but no ObjectAdded ever comes
  int unplug_after_objects = -1;  // >= 0: the camera vanishes after sending this many objects
  uint16_t fail_operation = 0;    // this operation is answered with fail_response (no data)
  uint16_t fail_response = 0;
};

class PtpResponder {
 public:
  explicit PtpResponder(ResponderOptions options);

  // Device side of the pipes; thread-safe. HandleBulkOut returns false once unplugged.
  bool HandleBulkOut(std::span<const uint8_t> bytes);
  // The next bulk-in transfer, at most `max_bytes`; nullopt when nothing is pending (or gone).
  std::optional<std::vector<uint8_t>> TakeBulkIn(size_t max_bytes);
  std::optional<std::vector<uint8_t>> TakeEvent();
  // Blocks until bulk-in data or an event is pending, the camera is unplugged, or `timeout`.
  void WaitForActivity(std::chrono::milliseconds timeout);

  void Unplug();
  bool unplugged() const;
  std::string DeviceName() const;
  size_t max_packet() const { return options_.max_packet; }

  // What happened, for assertions.
  struct Stats {
    int captures = 0;  // InitiateCapture answered OK
    int busy_answers = 0;
    int objects_sent = 0;  // GetObject data phases
    int objects_deleted = 0;
    int sessions_opened = 0;
    int sessions_closed = 0;
    std::vector<uint16_t> operations;       // in order received
    std::vector<uint32_t> transaction_ids;  // in order received
    int bulk_in_transfers = 0;
    int zero_length_packets = 0;
  };
  Stats stats() const;

 private:
  struct Object {
    std::vector<uint8_t> bytes;
    std::string filename;
  };

  void Answer(uint16_t code,
              uint32_t transaction,
              const std::vector<uint8_t>* data,
              uint16_t response,
              std::vector<uint32_t> response_params = {});
  void QueueBulkIn(std::vector<uint8_t> container);
  void Handle(uint16_t code, uint32_t transaction, const std::vector<uint32_t>& params);
  std::vector<uint8_t> DeviceInfoDataset() const;
  std::vector<uint8_t> ObjectInfoDataset(uint32_t handle, const Object& object) const;

  ResponderOptions options_;
  mutable std::mutex mutex_;
  std::condition_variable activity_;
  std::deque<std::vector<uint8_t>> bulk_in_;  // whole containers (an empty one is a ZLP)
  size_t bulk_in_offset_ = 0;                 // bytes of bulk_in_.front() already sent
  std::deque<std::pair<std::chrono::steady_clock::time_point, std::vector<uint8_t>>> events_;
  std::map<uint32_t, Object> objects_;
  uint32_t next_handle_ = 0x00010001;
  size_t next_jpeg_ = 0;
  bool session_open_ = false;
  bool unplugged_ = false;
  int busy_left_;
  Stats stats_;
};

// The responder behind the PtpTransport interface, in process (no USB at all).
std::unique_ptr<PtpTransport> MakeResponderTransport(std::shared_ptr<PtpResponder> responder);

// Hand-held shots for the camera to serve: the views of a small simulated Pop9 (3x3 lenses,
// `width` x `height` each, still_life scene) as JPEGs (quality 95), row-major. Rendered once
// per size and cached. Fails if the scene cannot be loaded.
struct HandHeldShots {
  std::vector<std::vector<uint8_t>> jpegs;
  std::vector<cv::Mat> bgr;  // the views before JPEG encoding, for comparisons
};
StatusOr<HandHeldShots> RenderHandHeldShots(int width, int height);

}  // namespace px::ptp::testing
