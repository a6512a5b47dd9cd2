// The "ptp" FrameSource over libusb, as the daemon opens it: a camera picked by USB ids (or the
// first PTP camera found). Nothing is opened until Configure, so the daemon starts without the
// camera and a camera plugged in later is found at the next Configure.
#pragma once

#include <chrono>
#include <memory>
#include <string>

#include "drivers/source/frame_source.h"

namespace px {

struct UsbPtpSourceOptions {
  std::string vendor_id;                          // 4 hex digits ("04a9"); "" = any vendor (the first PTP camera)
  std::string product_id;                         // 4 hex digits; "" = any product
  std::chrono::milliseconds shot_timeout{10000};  // InitiateCapture until ObjectAdded
};

// INVALID_ARGUMENT for ids that are not 4 hex digits (naming which).
StatusOr<std::unique_ptr<FrameSource>> OpenUsbPtpSource(const UsbPtpSourceOptions& options);

}  // namespace px
