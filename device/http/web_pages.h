// The pages: device/web's files at their names ("/" is index.html), and /api/token.svg, the
// access token as a QR code a phone can scan, shown only to a browser at the device itself.
#pragma once

#include <string>

#include "device/http/http_api.h"
#include "pipeline/core/status.h"

namespace px::device {

void RegisterWebPages(httplib::Server& server, const ApiContext& api);

// The machine's first non-loopback IPv4 address (where a phone on its network reaches it); ""
// when it has none.
std::string FirstNonLoopbackIpv4();

// An SVG of a QR code holding `text`; INVALID_ARGUMENT when it does not fit one.
StatusOr<std::string> QrCodeSvg(const std::string& text);

}  // namespace px::device
