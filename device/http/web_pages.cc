#include "device/http/web_pages.h"

#include <arpa/inet.h>
#include <httplib.h>
#include <ifaddrs.h>
#include <qrencode.h>

#include <memory>
#include <string_view>

#include "device/http/request_guard.h"
#include "device/http/web_assets.h"

namespace px::device {

namespace {

// Where a phone on the same network reaches this server: the listen address, or for a wildcard
// one the first non-loopback IPv4 address of the machine; "" when there is none.
std::string ReachableAddress(const std::string& listen_host) {
  if (listen_host != "0.0.0.0" && listen_host != "::" && !IsLoopbackAddress(listen_host)) return listen_host;
  if (listen_host != "0.0.0.0" && listen_host != "::") return "";
  return FirstNonLoopbackIpv4();
}

void TokenQrCode(const ApiContext& api, const httplib::Request& req, httplib::Response& res) {
  if (!IsLoopbackAddress(req.remote_addr) || !IsLoopbackHost(req.get_header_value("Host"))) {
    res.status = 403;
    res.set_content(R"({"ok":false,"error":"the token's QR code is shown only at the device"})", "application/json");
    return;
  }
  const std::string address = ReachableAddress(api.listen_host);
  // The token rides in the fragment, which a browser never sends to a server or writes to a log.
  const std::string text =
      address.empty() ? api.token
                      : "http://" + address + ":" + std::to_string(req.local_port) + "/login.html#token=" + api.token;
  StatusOr<std::string> svg = QrCodeSvg(text);
  if (!svg.ok()) {
    res.status = 500;
    res.set_content(R"({"ok":false,"error":"QR code"})", "application/json");
    return;
  }
  res.set_header("Cache-Control", "no-store");
  res.set_header("X-Parallax-Login-Url", address.empty() ? "" : text.substr(0, text.find('#')));
  res.set_content(*svg, "image/svg+xml");
}

}  // namespace

std::string FirstNonLoopbackIpv4() {
  ifaddrs* list = nullptr;
  if (getifaddrs(&list) != 0) return "";
  std::string found;
  for (ifaddrs* it = list; it != nullptr && found.empty(); it = it->ifa_next) {
    if (it->ifa_addr == nullptr || it->ifa_addr->sa_family != AF_INET) continue;
    char text[INET_ADDRSTRLEN] = {};
    const auto* address = reinterpret_cast<const sockaddr_in*>(it->ifa_addr);
    if (inet_ntop(AF_INET, &address->sin_addr, text, sizeof(text)) != nullptr && !IsLoopbackAddress(text)) found = text;
  }
  freeifaddrs(list);
  return found;
}

StatusOr<std::string> QrCodeSvg(const std::string& text) {
  std::unique_ptr<QRcode, void (*)(QRcode*)> code(QRcode_encodeString(text.c_str(), 0, QR_ECLEVEL_M, QR_MODE_8, 1),
                                                  QRcode_free);
  if (!code) return InvalidArgumentError("QR code: " + std::to_string(text.size()) + " bytes do not fit");
  const int width = code->width;
  constexpr int kQuiet = 4;  // the quiet zone a reader needs around the code, in modules
  const int size = width + 2 * kQuiet;
  std::string path;
  for (int y = 0; y < width; ++y) {
    for (int x = 0; x < width; ++x) {
      if (code->data[y * width + x] & 1) {
        path += "M" + std::to_string(x + kQuiet) + " " + std::to_string(y + kQuiet) + "h1v1h-1z";
      }
    }
  }
  return "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 " + std::to_string(size) + " " +
         std::to_string(size) + "\" shape-rendering=\"crispEdges\"><rect width=\"100%\" height=\"100%\" " +
         "fill=\"#fff\"/><path fill=\"#000\" d=\"" + path + "\"/></svg>";
}

void RegisterWebPages(httplib::Server& server, const ApiContext& api) {
  for (const EmbeddedFile& file : WebAssets()) {
    const std::string type = ContentTypeFor(std::string(file.name));
    const std::string_view bytes = file.bytes;
    auto serve = [bytes, type](const httplib::Request&, httplib::Response& res) {
      res.set_header("Cache-Control", "no-cache");
      res.set_content(bytes.data(), bytes.size(), type.c_str());
    };
    server.Get("/" + std::string(file.name), serve);
    if (file.name == "index.html") server.Get("/", serve);
  }
  server.Get("/api/token.svg",
             [api](const httplib::Request& req, httplib::Response& res) { TokenQrCode(api, req, res); });
}

}  // namespace px::device
