#include "tests/drivers/ptp_umockdev_camera.h"

#include <linux/usbdevice_fs.h>
#include <sys/ioctl.h>
#include <umockdev.h>

#include <cerrno>
#include <cstddef>
#include <cstdio>
#include <deque>
#include <fstream>
#include <mutex>

namespace px::ptp::testing {
namespace {

using std::chrono::milliseconds;

constexpr uint8_t kBulkIn = 0x81;
constexpr uint8_t kBulkOut = 0x02;
constexpr uint8_t kInterruptIn = 0x83;
constexpr uint16_t kInterruptPacket = 64;

std::vector<uint8_t> Descriptors(const PtpResponder& responder, uint16_t vendor, uint16_t product, bool ptp_class) {
  const uint16_t packet = static_cast<uint16_t>(responder.max_packet());
  auto lo = [](uint16_t v) { return static_cast<uint8_t>(v & 0xff); };
  auto hi = [](uint16_t v) { return static_cast<uint8_t>(v >> 8); };
  std::vector<uint8_t> d = {
      18,
      1,
      0x00,
      0x02,
      0,
      0,
      0,
      64,
      lo(vendor),
      hi(vendor),
      lo(product),
      hi(product),
      0x00,
      0x01,
      0,
      0,
      0,
      1,
      // configuration: 9 + 9 + 3 * 7 = 39 bytes
      9,
      2,
      39,
      0,
      1,
      1,
      0,
      0xC0,
      50,
      // interface 0: still image (6/1/1) or vendor specific
      9,
      4,
      0,
      0,
      3,
      static_cast<uint8_t>(ptp_class ? 6 : 0xFF),
      static_cast<uint8_t>(ptp_class ? 1 : 0xFF),
      static_cast<uint8_t>(ptp_class ? 1 : 0xFF),
      0,
      7,
      5,
      kBulkIn,
      2,
      lo(packet),
      hi(packet),
      0,
      7,
      5,
      kBulkOut,
      2,
      lo(packet),
      hi(packet),
      0,
      7,
      5,
      kInterruptIn,
      3,
      lo(kInterruptPacket),
      hi(kInterruptPacket),
      8,
  };
  return d;
}

std::string Hex(const std::vector<uint8_t>& bytes) {
  std::string text;
  char pair[3];
  for (uint8_t b : bytes) {
    std::snprintf(pair, sizeof(pair), "%02X", b);  // umockdev reads upper-case hex only
    text += pair;
  }
  return text;
}

}  // namespace

struct UmockdevPtpCamera::Impl {
  struct Urb {
    UMockdevIoctlData* urb = nullptr;     // our reference to the client's usbdevfs_urb
    UMockdevIoctlData* buffer = nullptr;  // and to its buffer
    uint8_t endpoint = 0;
    int status = 0;
    int actual = 0;
  };

  std::shared_ptr<PtpResponder> responder;
  UmockdevCameraOptions options;
  UMockdevTestbed* testbed = nullptr;
  UMockdevIoctlBase* handler = nullptr;
  std::string syspath;
  std::string node;

  mutable std::mutex mutex;
  std::deque<Urb> pending;    // submitted IN URBs waiting for data
  std::deque<Urb> completed;  // ready to be reaped
  Counters counters;

  ~Impl() {
    if (testbed) {
      if (!node.empty()) umockdev_testbed_detach_ioctl(testbed, node.c_str(), nullptr);
      g_object_unref(testbed);
    }
    if (handler) g_object_unref(handler);
    for (auto* queue : {&pending, &completed}) {
      for (Urb& urb : *queue) Release(&urb);
    }
  }

  static void Release(Urb* urb) {
    if (urb->buffer) g_object_unref(urb->buffer);
    if (urb->urb) g_object_unref(urb->urb);
    urb->buffer = nullptr;
    urb->urb = nullptr;
  }

  static gboolean OnIoctl(UMockdevIoctlBase*, UMockdevIoctlClient* client, gpointer self) {
    return static_cast<Impl*>(self)->Handle(client);
  }

  void Complete(UMockdevIoctlClient* client, long result, int error) {
    umockdev_ioctl_client_complete(client, result, error);
  }

  // Moves pending IN URBs that the responder can fill (or that a lost device ends) to completed.
  void Progress() {
    const bool gone = responder->unplugged();
    for (auto it = pending.begin(); it != pending.end();) {
      if (gone) {
        it->status = -ENODEV;
      } else {
        const int length = reinterpret_cast<usbdevfs_urb*>(it->urb->data)->buffer_length;
        auto bytes =
            it->endpoint == kInterruptIn ? responder->TakeEvent() : responder->TakeBulkIn(static_cast<size_t>(length));
        if (!bytes) {
          ++it;
          continue;
        }
        if (!bytes->empty()) umockdev_ioctl_data_update(it->buffer, 0, bytes->data(), static_cast<int>(bytes->size()));
        it->actual = static_cast<int>(bytes->size());
        it->status = 0;
      }
      completed.push_back(*it);
      it = pending.erase(it);
    }
  }

  gboolean Handle(UMockdevIoctlClient* client) {
    const unsigned long request = umockdev_ioctl_client_get_request(client);
    UMockdevIoctlData* arg = umockdev_ioctl_client_get_arg(client);
    std::lock_guard lock(mutex);
    switch (request) {
      case USBDEVFS_GET_CAPABILITIES: {
        UMockdevIoctlData* data = umockdev_ioctl_data_resolve(arg, 0, sizeof(uint32_t), nullptr);
        // An xHCI host: scatter-gather lets libusb submit each transfer as one URB.
        uint32_t caps = USBDEVFS_CAP_BULK_SCATTER_GATHER | USBDEVFS_CAP_NO_PACKET_SIZE_LIM |
                        USBDEVFS_CAP_REAP_AFTER_DISCONNECT | USBDEVFS_CAP_ZERO_PACKET;
        umockdev_ioctl_data_update(data, 0, reinterpret_cast<guint8*>(&caps), sizeof(caps));
        g_object_unref(data);
        Complete(client, 0, 0);
        return TRUE;
      }
      case USBDEVFS_GETDRIVER:
        Complete(client, -1, ENODATA);  // no kernel driver bound
        return TRUE;
      case USBDEVFS_CLAIMINTERFACE:
        ++counters.claims;
        if (responder->unplugged()) {
          Complete(client, -1, ENODEV);
        } else if (options.claim_errno != 0) {
          Complete(client, -1, options.claim_errno);
        } else {
          Complete(client, 0, 0);
        }
        return TRUE;
      case USBDEVFS_RELEASEINTERFACE:
      case USBDEVFS_CLEAR_HALT:
      case USBDEVFS_RESETEP:
      case USBDEVFS_SETINTERFACE:
        Complete(client, 0, 0);
        return TRUE;
      case USBDEVFS_CONTROL: {
        UMockdevIoctlData* data = umockdev_ioctl_data_resolve(arg, 0, sizeof(usbdevfs_ctrltransfer), nullptr);
        auto* control = reinterpret_cast<usbdevfs_ctrltransfer*>(data->data);
        if (control->bRequest == 0x08 && control->wLength >= 1) {  // GET_CONFIGURATION
          UMockdevIoctlData* buffer =
              umockdev_ioctl_data_resolve(data, offsetof(usbdevfs_ctrltransfer, data), control->wLength, nullptr);
          guint8 configuration = 1;
          umockdev_ioctl_data_update(buffer, 0, &configuration, 1);
          g_object_unref(buffer);
          Complete(client, 1, 0);
        } else {
          Complete(client, -1, EPIPE);
        }
        g_object_unref(data);
        return TRUE;
      }
      case USBDEVFS_SUBMITURB: {
        ++counters.submitted;
        if (responder->unplugged()) {
          Complete(client, -1, ENODEV);
          return TRUE;
        }
        Urb urb;
        urb.urb = umockdev_ioctl_data_resolve(arg, 0, sizeof(usbdevfs_urb), nullptr);
        auto* raw = reinterpret_cast<usbdevfs_urb*>(urb.urb->data);
        urb.endpoint = raw->endpoint;
        urb.buffer =
            raw->buffer_length > 0
                ? umockdev_ioctl_data_resolve(
                      urb.urb, offsetof(usbdevfs_urb, buffer), static_cast<size_t>(raw->buffer_length), nullptr)
                : nullptr;
        if (urb.endpoint == kBulkOut) {
          const bool accepted = responder->HandleBulkOut(std::span<const uint8_t>(
              urb.buffer ? urb.buffer->data : nullptr, static_cast<size_t>(raw->buffer_length)));
          urb.status = accepted ? 0 : -ENODEV;
          urb.actual = accepted ? raw->buffer_length : 0;
          completed.push_back(urb);
        } else if (urb.endpoint == kBulkIn || urb.endpoint == kInterruptIn) {
          pending.push_back(urb);
        } else {
          Release(&urb);
          Complete(client, -1, EINVAL);
          return TRUE;
        }
        Complete(client, 0, 0);
        return TRUE;
      }
      case USBDEVFS_DISCARDURB: {
        const unsigned long address = *reinterpret_cast<unsigned long*>(arg->data);
        for (auto it = pending.begin(); it != pending.end(); ++it) {
          if (it->urb->client_addr == address) {
            it->status = -ENOENT;
            it->actual = 0;
            completed.push_back(*it);
            pending.erase(it);
            ++counters.discarded;
            Complete(client, 0, 0);
            return TRUE;
          }
        }
        Complete(client, -1, EINVAL);  // already completed
        return TRUE;
      }
      case USBDEVFS_REAPURB:
      case USBDEVFS_REAPURBNDELAY: {
        Progress();
        if (completed.empty() && !pending.empty()) {
          // REAPURBNDELAY must not block, but a short wait keeps libusb's poll loop (a regular
          // file is always writable) from spinning flat out while the camera has nothing to say.
          mutex.unlock();
          responder->WaitForActivity(milliseconds(2));
          mutex.lock();
          Progress();
        }
        if (completed.empty()) {
          Complete(client, -1, responder->unplugged() ? ENODEV : EAGAIN);
          return TRUE;
        }
        Urb urb = completed.front();
        completed.pop_front();
        int status = urb.status;
        int actual = urb.actual;
        umockdev_ioctl_data_update(
            urb.urb, offsetof(usbdevfs_urb, status), reinterpret_cast<guint8*>(&status), sizeof(status));
        umockdev_ioctl_data_update(
            urb.urb, offsetof(usbdevfs_urb, actual_length), reinterpret_cast<guint8*>(&actual), sizeof(actual));
        UMockdevIoctlData* data = umockdev_ioctl_data_resolve(arg, 0, sizeof(void*), nullptr);
        umockdev_ioctl_data_set_ptr(data, 0, urb.urb);
        g_object_unref(data);
        ++counters.reaped;
        Complete(client, 0, 0);
        Release(&urb);
        return TRUE;
      }
      default:
        Complete(client, -1, ENOTTY);
        return TRUE;
    }
  }
};

Status CheckUmockdevEnvironment() {
  // umockdev_in_mock_environment() is only true once a testbed exists; look for the library.
  std::ifstream maps("/proc/self/maps");
  std::string line;
  bool preloaded = false;
  while (!preloaded && std::getline(maps, line)) preloaded = line.find("libumockdev-preload") != std::string::npos;
  if (!preloaded) {
    return UnavailableError(
        "not running under umockdev: the test needs LD_PRELOAD=libumockdev-preload.so.0 (ctest sets it)");
  }
  return OkStatus();
}

UmockdevPtpCamera::UmockdevPtpCamera(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
UmockdevPtpCamera::~UmockdevPtpCamera() = default;

std::string UmockdevPtpCamera::DeviceNode() const { return impl_->node; }

UmockdevPtpCamera::Counters UmockdevPtpCamera::counters() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->counters;
}

StatusOr<std::unique_ptr<UmockdevPtpCamera>> UmockdevPtpCamera::Create(std::shared_ptr<PtpResponder> responder,
                                                                       UmockdevCameraOptions options) {
  PX_RETURN_IF_ERROR(CheckUmockdevEnvironment());
  auto impl = std::make_unique<Impl>();
  impl->responder = responder;
  impl->options = options;
  impl->testbed = umockdev_testbed_new();

  const std::string name = responder->DeviceName();  // "sim-ptp (1d6b:0104)"
  unsigned vendor = 0;
  unsigned product = 0;
  std::sscanf(name.c_str(), "sim-ptp (%x:%x)", &vendor, &product);
  const std::string descriptors =
      Hex(Descriptors(*responder, static_cast<uint16_t>(vendor), static_cast<uint16_t>(product), options.ptp_class));
  char bus[8];
  char address[8];
  std::snprintf(bus, sizeof(bus), "%03d", options.bus);
  std::snprintf(address, sizeof(address), "%03d", options.address);
  char ids[32];
  std::snprintf(ids, sizeof(ids), "%04x:%04x", vendor, product);
  impl->node = std::string("/dev/bus/usb/") + bus + "/" + address;
  const std::string sysname = std::to_string(options.bus) + "-1";
  impl->syspath = "/sys/devices/pci0000:00/0000:00:14.0/usb" + std::to_string(options.bus) + "/" + sysname;
  const std::string record =
      "P: /devices/pci0000:00/0000:00:14.0/usb" + std::to_string(options.bus) + "/" + sysname + "\n" + "N: bus/usb/" +
      bus + "/" + address + "=" + descriptors + "\n" + "E: DEVNAME=" + impl->node + "\n" +
      "E: DEVTYPE=usb_device\nE: DRIVER=usb\nE: SUBSYSTEM=usb\n" + "E: BUSNUM=" + bus + "\nE: DEVNUM=" + address +
      "\n" + "E: PRODUCT=" + std::string(ids).replace(4, 1, "/") + "/100\n" +
      // Attribute values end in a newline, as sysfs files do (the record escapes it as \n).
      "A: busnum=" + std::to_string(options.bus) + "\\n\nA: devnum=" + std::to_string(options.address) + "\\n\n" +
      "A: speed=480\\n\nA: bConfigurationValue=1\\n\nA: bNumInterfaces= 1\\n\n" + "A: idVendor=" + std::string(ids, 4) +
      "\\n\nA: idProduct=" + std::string(ids + 5, 4) + "\\n\n" + "H: descriptors=" + descriptors + "\n";
  GError* error = nullptr;
  if (!umockdev_testbed_add_from_string(impl->testbed, record.c_str(), &error)) {
    std::string message = error ? error->message : "unknown error";
    if (error) g_error_free(error);
    return InternalError("umockdev: adding the USB camera failed: " + message + "\n" + record);
  }
  impl->handler = umockdev_ioctl_base_new();
  g_signal_connect(impl->handler, "handle-ioctl", G_CALLBACK(&Impl::OnIoctl), impl.get());
  if (!umockdev_testbed_attach_ioctl(impl->testbed, impl->node.c_str(), impl->handler, &error)) {
    std::string message = error ? error->message : "unknown error";
    if (error) g_error_free(error);
    const std::string node = impl->node;
    impl->node.clear();
    return InternalError("umockdev: attaching the ioctl handler to " + node + " failed: " + message);
  }
  return std::unique_ptr<UmockdevPtpCamera>(new UmockdevPtpCamera(std::move(impl)));
}

}  // namespace px::ptp::testing
