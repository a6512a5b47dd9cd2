// The three pipes of a PTP-over-USB camera (bulk out, bulk in, interrupt in), so the session can
// run over libusb (libusb_transport.h) or over a simulated camera in tests.
//
// Error convention every implementation follows:
//   DEADLINE_EXCEEDED  the timeout passed with no data (nothing is lost; the call may be retried)
//   UNAVAILABLE        the device has gone (unplugged); the message names the device
//   anything else      a transfer failed (stall, overflow, I/O error), named with the device
#pragma once

#include <chrono>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "pipeline/core/status.h"

namespace px::ptp {

class PtpTransport {
 public:
  virtual ~PtpTransport() = default;

  // Names the device in messages: "usb 001/005 (04a9:3218)".
  virtual std::string DeviceName() const = 0;
  // The bulk-in endpoint's wMaxPacketSize (a data phase ends with a packet shorter than this).
  virtual size_t MaxPacketBytes() const = 0;

  // Sends all of `bytes` as one bulk-out transfer.
  virtual Status BulkOut(std::span<const uint8_t> bytes, std::chrono::milliseconds timeout) = 0;
  // One bulk-in transfer of at most `max_bytes` (a multiple of MaxPacketBytes()); it ends early
  // at a short packet. A zero-length packet gives an empty vector.
  virtual StatusOr<std::vector<uint8_t>> BulkIn(size_t max_bytes, std::chrono::milliseconds timeout) = 0;
  // One interrupt-in transfer (an event container) of at most `max_bytes`.
  virtual StatusOr<std::vector<uint8_t>> InterruptIn(size_t max_bytes, std::chrono::milliseconds timeout) = 0;
};

}  // namespace px::ptp
