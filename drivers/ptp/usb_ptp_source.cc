#include "drivers/ptp/usb_ptp_source.h"

#include "drivers/ptp/libusb_transport.h"
#include "drivers/ptp/ptp_source.h"

namespace px {
namespace {

StatusOr<uint16_t> ParseUsbId(const std::string& text, const std::string& field) {
  if (text.empty()) return uint16_t{0};
  if (text.size() != 4 || text.find_first_not_of("0123456789abcdefABCDEF") != std::string::npos) {
    return InvalidArgumentError(field + ": '" + text + "' is not 4 hex digits");
  }
  return static_cast<uint16_t>(std::stoul(text, nullptr, 16));
}

}  // namespace

StatusOr<std::unique_ptr<FrameSource>> OpenUsbPtpSource(const UsbPtpSourceOptions& options) {
  ptp::LibusbTransportOptions usb;
  PX_ASSIGN_OR_RETURN(usb.vendor_id, ParseUsbId(options.vendor_id, "vendor_id"));
  PX_ASSIGN_OR_RETURN(usb.product_id, ParseUsbId(options.product_id, "product_id"));
  PtpSourceOptions source;
  source.label = options.vendor_id.empty()
                     ? "usb (first PTP camera)"
                     : "usb " + options.vendor_id + ":" + (options.product_id.empty() ? "*" : options.product_id);
  source.shot_timeout = options.shot_timeout;
  source.open_transport = [usb] { return ptp::OpenLibusbTransport(usb); };
  return MakePtpSource(std::move(source));
}

}  // namespace px
