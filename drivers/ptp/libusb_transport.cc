#include "drivers/ptp/libusb_transport.h"

#include <libusb.h>

#include <cstdio>
#include <optional>

#include "pipeline/core/log.h"

namespace px::ptp {
namespace {

using std::chrono::milliseconds;

constexpr uint8_t kStillImageClass = 6;  // USB class 6 subclass 1 protocol 1: PIMA 15740 PTP
constexpr uint8_t kStillImageSubclass = 1;
constexpr uint8_t kStillImageProtocol = 1;

std::string DeviceLabel(libusb_device* device, const libusb_device_descriptor& descriptor) {
  char text[64];
  std::snprintf(text,
                sizeof(text),
                "usb %03d/%03d (%04x:%04x)",
                libusb_get_bus_number(device),
                libusb_get_device_address(device),
                descriptor.idVendor,
                descriptor.idProduct);
  return text;
}

std::string Hex4(uint16_t value) {
  char text[8];
  std::snprintf(text, sizeof(text), "%04x", value);
  return text;
}

// The explanation a user needs when the camera is there but cannot be had.
std::string WhyBusy() {
  return "another program has claimed the camera; on desktops this is usually gvfs-gphoto2-volume-monitor "
         "(stop it with `systemctl --user stop gvfs-gphoto2-volume-monitor` or `gio mount -u gphoto2://*`), "
         "or a running gphoto2/gtkam/darktable tether; quit it and try again";
}

std::string WhyAccess() {
  return "the USB device node is not writable by this user (run as root or install a udev rule giving access, "
         "e.g. libgphoto2's 'camera' rules), or " +
         WhyBusy();
}

Status UsbStatus(int error, const std::string& where) {
  const std::string name = libusb_error_name(error);
  switch (error) {
    case LIBUSB_ERROR_TIMEOUT:
      return DeadlineExceededError(where + ": timed out (" + name + ")");
    case LIBUSB_ERROR_NO_DEVICE:
      return UnavailableError(where + ": the camera has been disconnected (" + name + ")");
    case LIBUSB_ERROR_BUSY:
      return FailedPreconditionError(where + ": " + name + ": " + WhyBusy());
    case LIBUSB_ERROR_ACCESS:
      return FailedPreconditionError(where + ": " + name + ": " + WhyAccess());
    case LIBUSB_ERROR_OVERFLOW:
      return DataLossError(where + ": the camera sent more than was asked for (" + name + ")");
    case LIBUSB_ERROR_PIPE:
      return DataLossError(where + ": the endpoint stalled (" + name + ")");
    default:
      return InternalError(where + ": " + name);
  }
}

struct Endpoints {
  int interface_number = -1;
  uint8_t bulk_in = 0;
  uint8_t bulk_out = 0;
  uint8_t interrupt_in = 0;
  size_t bulk_in_packet = 512;
};

// The first interface of `device` that is a still-image interface (or, with `any_class`, any
// interface with the three PTP endpoints).
std::optional<Endpoints> FindPtpInterface(libusb_device* device, bool any_class) {
  libusb_config_descriptor* config = nullptr;
  if (libusb_get_active_config_descriptor(device, &config) != 0 &&
      libusb_get_config_descriptor(device, 0, &config) != 0) {
    return std::nullopt;
  }
  std::optional<Endpoints> found;
  for (int i = 0; i < config->bNumInterfaces && !found; ++i) {
    const libusb_interface& interface = config->interface[i];
    for (int a = 0; a < interface.num_altsetting && !found; ++a) {
      const libusb_interface_descriptor& alt = interface.altsetting[a];
      const bool still_image = alt.bInterfaceClass == kStillImageClass &&
                               alt.bInterfaceSubClass == kStillImageSubclass &&
                               alt.bInterfaceProtocol == kStillImageProtocol;
      if (!still_image && !any_class) continue;
      Endpoints endpoints;
      endpoints.interface_number = alt.bInterfaceNumber;
      for (int e = 0; e < alt.bNumEndpoints; ++e) {
        const libusb_endpoint_descriptor& ep = alt.endpoint[e];
        const int type = ep.bmAttributes & LIBUSB_TRANSFER_TYPE_MASK;
        const bool in = (ep.bEndpointAddress & LIBUSB_ENDPOINT_DIR_MASK) == LIBUSB_ENDPOINT_IN;
        if (type == LIBUSB_TRANSFER_TYPE_BULK && in && !endpoints.bulk_in) {
          endpoints.bulk_in = ep.bEndpointAddress;
          endpoints.bulk_in_packet = ep.wMaxPacketSize ? ep.wMaxPacketSize : 512;
        } else if (type == LIBUSB_TRANSFER_TYPE_BULK && !in && !endpoints.bulk_out) {
          endpoints.bulk_out = ep.bEndpointAddress;
        } else if (type == LIBUSB_TRANSFER_TYPE_INTERRUPT && in && !endpoints.interrupt_in) {
          endpoints.interrupt_in = ep.bEndpointAddress;
        }
      }
      if (endpoints.bulk_in && endpoints.bulk_out && endpoints.interrupt_in) found = endpoints;
    }
  }
  libusb_free_config_descriptor(config);
  return found;
}

unsigned int TimeoutMs(milliseconds timeout) {
  return static_cast<unsigned int>(std::clamp<int64_t>(timeout.count(), 1, 600000));  // 0 would mean forever
}

class LibusbTransport final : public PtpTransport {
 public:
  LibusbTransport(
      libusb_context* context, libusb_device_handle* handle, Endpoints endpoints, std::string name, bool reattach)
      : context_(context), handle_(handle), endpoints_(endpoints), name_(std::move(name)), reattach_(reattach) {}

  ~LibusbTransport() override {
    libusb_release_interface(handle_, endpoints_.interface_number);
    if (reattach_) libusb_attach_kernel_driver(handle_, endpoints_.interface_number);
    libusb_close(handle_);
    libusb_exit(context_);
  }

  std::string DeviceName() const override { return name_; }
  size_t MaxPacketBytes() const override { return endpoints_.bulk_in_packet; }

  Status BulkOut(std::span<const uint8_t> bytes, milliseconds timeout) override {
    int sent = 0;
    const int r = libusb_bulk_transfer(handle_,
                                       endpoints_.bulk_out,
                                       const_cast<uint8_t*>(bytes.data()),
                                       static_cast<int>(bytes.size()),
                                       &sent,
                                       TimeoutMs(timeout));
    if (r != 0) return UsbStatus(r, name_ + " bulk-out");
    if (static_cast<size_t>(sent) != bytes.size()) {
      return DataLossError(name_ + " bulk-out: sent " + std::to_string(sent) + " of " + std::to_string(bytes.size()) +
                           " bytes");
    }
    return OkStatus();
  }

  StatusOr<std::vector<uint8_t>> BulkIn(size_t max_bytes, milliseconds timeout) override {
    return In(endpoints_.bulk_in, max_bytes, timeout, "bulk-in", libusb_bulk_transfer);
  }

  StatusOr<std::vector<uint8_t>> InterruptIn(size_t max_bytes, milliseconds timeout) override {
    return In(endpoints_.interrupt_in, max_bytes, timeout, "interrupt-in", libusb_interrupt_transfer);
  }

 private:
  using TransferFn = int (*)(libusb_device_handle*, unsigned char, unsigned char*, int, int*, unsigned int);

  StatusOr<std::vector<uint8_t>> In(
      uint8_t endpoint, size_t max_bytes, milliseconds timeout, const char* pipe, TransferFn transfer) {
    std::vector<uint8_t> bytes(max_bytes);
    int got = 0;
    const int r = transfer(handle_, endpoint, bytes.data(), static_cast<int>(bytes.size()), &got, TimeoutMs(timeout));
    // A timeout after some bytes arrived still delivers them.
    if (r != 0 && !(r == LIBUSB_ERROR_TIMEOUT && got > 0)) return UsbStatus(r, name_ + " " + pipe);
    bytes.resize(static_cast<size_t>(got));
    return bytes;
  }

  libusb_context* context_;
  libusb_device_handle* handle_;
  Endpoints endpoints_;
  std::string name_;
  bool reattach_;
};

}  // namespace

StatusOr<LibusbTransportOptions> ParseVendorProduct(const std::string& text) {
  LibusbTransportOptions options;
  if (text.empty()) return options;
  unsigned vendor = 0;
  unsigned product = 0;
  int consumed = 0;
  if (std::sscanf(text.c_str(), "%4x:%4x%n", &vendor, &product, &consumed) != 2 ||
      consumed != static_cast<int>(text.size())) {
    return InvalidArgumentError("'" + text + "' is not a USB vendor:product like 04a9:3218");
  }
  options.vendor_id = static_cast<uint16_t>(vendor);
  options.product_id = static_cast<uint16_t>(product);
  return options;
}

StatusOr<std::unique_ptr<PtpTransport>> OpenLibusbTransport(const LibusbTransportOptions& options) {
  libusb_context* context = nullptr;
  if (int r = libusb_init(&context); r != 0) {
    return UnavailableError(std::string("libusb_init: ") + libusb_error_name(r));
  }
  libusb_device** list = nullptr;
  const ssize_t count = libusb_get_device_list(context, &list);
  if (count < 0) {
    libusb_exit(context);
    return UnavailableError(std::string("libusb_get_device_list: ") + libusb_error_name(static_cast<int>(count)));
  }
  const bool by_id = options.vendor_id != 0 || options.product_id != 0;
  libusb_device* chosen = nullptr;
  libusb_device_descriptor chosen_descriptor{};
  Endpoints endpoints;
  for (ssize_t i = 0; i < count && !chosen; ++i) {
    libusb_device_descriptor descriptor{};
    if (libusb_get_device_descriptor(list[i], &descriptor) != 0) continue;
    if (options.vendor_id != 0 && descriptor.idVendor != options.vendor_id) continue;
    if (options.product_id != 0 && descriptor.idProduct != options.product_id) continue;
    // A device named by vendor:product may use a vendor-specific class with PTP endpoints.
    auto found = FindPtpInterface(list[i], /*any_class=*/false);
    if (!found && by_id) found = FindPtpInterface(list[i], /*any_class=*/true);
    if (!found) continue;
    chosen = list[i];
    chosen_descriptor = descriptor;
    endpoints = *found;
  }
  if (!chosen) {
    libusb_free_device_list(list, 1);
    libusb_exit(context);
    const std::string wanted =
        by_id ? "USB device " + Hex4(options.vendor_id) + ":" + Hex4(options.product_id) + " with PTP endpoints"
              : "PTP camera (a USB still-image interface, class 6/1/1)";
    return NotFoundError("no " + wanted + " among " + std::to_string(count) +
                         " USB devices; is the camera on and in PTP (not mass storage) mode?");
  }
  const std::string name = DeviceLabel(chosen, chosen_descriptor);
  libusb_device_handle* handle = nullptr;
  const int opened = libusb_open(chosen, &handle);
  libusb_free_device_list(list, 1);
  if (opened != 0) {
    libusb_exit(context);
    return UsbStatus(opened, "opening " + name);
  }
  auto fail = [&](int r, const std::string& action) {
    libusb_close(handle);
    libusb_exit(context);
    return UsbStatus(r, action + " " + name + " interface " + std::to_string(endpoints.interface_number));
  };
  bool reattach = false;
  const int active = libusb_kernel_driver_active(handle, endpoints.interface_number);
  if (active == 1) {
    if (int r = libusb_detach_kernel_driver(handle, endpoints.interface_number); r != 0) {
      return fail(r, "detaching the kernel driver from");
    }
    reattach = true;
  }
  if (int r = libusb_claim_interface(handle, endpoints.interface_number); r != 0) {
    return fail(r, "claiming");
  }
  Logger("ptp")->info("{}: claimed interface {} (bulk in 0x{:02x}, out 0x{:02x}, interrupt 0x{:02x})",
                      name,
                      endpoints.interface_number,
                      endpoints.bulk_in,
                      endpoints.bulk_out,
                      endpoints.interrupt_in);
  return std::unique_ptr<PtpTransport>(std::make_unique<LibusbTransport>(context, handle, endpoints, name, reattach));
}

}  // namespace px::ptp
