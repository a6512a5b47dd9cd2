// The simulated PTP camera behind a real USB device node, for testing the libusb transport:
// a umockdev testbed holds a USB device with a still-image interface (class 6/1/1, bulk in
// 0x81, bulk out 0x02, interrupt in 0x83), and an ioctl handler answers libusb's usbdevfs calls
// (GET_CAPABILITIES, GETDRIVER, CLAIM/RELEASEINTERFACE, CONTROL, SUBMITURB, REAPURBNDELAY,
// DISCARDURB) by passing bulk and interrupt URBs to a PtpResponder. Needs the process to run
// with LD_PRELOAD=libumockdev-preload.so.0.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "pipeline/core/status.h"
#include "tests/drivers/ptp_responder.h"

namespace px::ptp::testing {

struct UmockdevCameraOptions {
  int bus = 1;
  int address = 5;
  int claim_errno = 0;    // CLAIMINTERFACE fails with this errno (EBUSY: another program has it)
  bool ptp_class = true;  // false: a vendor-specific interface class (found only by vendor:product)
};

// UNAVAILABLE (with the reason) when not running under umockdev's preload library.
Status CheckUmockdevEnvironment();

class UmockdevPtpCamera {
 public:
  static StatusOr<std::unique_ptr<UmockdevPtpCamera>> Create(std::shared_ptr<PtpResponder> responder,
                                                             UmockdevCameraOptions options = {});
  ~UmockdevPtpCamera();
  UmockdevPtpCamera(const UmockdevPtpCamera&) = delete;
  UmockdevPtpCamera& operator=(const UmockdevPtpCamera&) = delete;

  std::string DeviceNode() const;  // "/dev/bus/usb/001/005"

  struct Counters {
    int submitted = 0;
    int reaped = 0;
    int discarded = 0;
    int claims = 0;
  };
  Counters counters() const;

  struct Impl;

 private:
  explicit UmockdevPtpCamera(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace px::ptp::testing
