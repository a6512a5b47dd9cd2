// PtpTransport over libusb-1.0: finds a camera (a still-image interface, USB class 6 subclass 1
// protocol 1, or a given vendor:product), detaches a kernel driver if one is bound, claims the
// interface and moves bytes on its bulk-in, bulk-out and interrupt-in endpoints.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "drivers/ptp/ptp_transport.h"

namespace px::ptp {

struct LibusbTransportOptions {
  uint16_t vendor_id = 0;   // 0 = any vendor
  uint16_t product_id = 0;  // 0 = any product
};

// NOT_FOUND when no camera matches (the message says what was looked for among how many
// devices); FAILED_PRECONDITION when the camera is there but cannot be used: LIBUSB_ERROR_BUSY
// or LIBUSB_ERROR_ACCESS (another program such as gvfs-gphoto2-volume-monitor or gphoto2 holds
// it, or the device node is not writable), naming the device (bus/address, vendor:product).
StatusOr<std::unique_ptr<PtpTransport>> OpenLibusbTransport(const LibusbTransportOptions& options);

// "04a9:3218" -> {0x04a9, 0x3218}; "" -> {0, 0}. INVALID_ARGUMENT otherwise.
StatusOr<LibusbTransportOptions> ParseVendorProduct(const std::string& text);

}  // namespace px::ptp
