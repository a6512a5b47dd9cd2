// Who may do what over HTTP, decided from the request's facts alone (no sockets, so it is tested
// directly). The rules:
// - A request from loopback whose Host names loopback (localhost, 127.x.y.z, [::1]) is the
//   device's owner at the device: no token needed (unless token_required is "always"). The Host
//   check stops DNS rebinding: a page from evil.example that resolves to 127.0.0.1 sends
//   Host: evil.example and must show the token like any remote client.
// - Anyone else presents the token, as "Authorization: Bearer TOKEN" or the px_token cookie the
//   login page sets. Without it: 401.
// - A state-changing request (POST, PUT, PATCH, DELETE) whose Origin is not this server's own
//   (scheme://Host) is refused with 403 (CSRF), whatever its credentials.
// - The login page, the login call and the style sheet are open to all: they reveal nothing.
#pragma once

#include <string>
#include <string_view>

namespace px::device {

bool IsLoopbackAddress(std::string_view address);
// The host part of a Host header ("localhost:8080" -> "localhost", "[::1]:80" -> "::1") names
// loopback.
bool IsLoopbackHost(std::string_view host_header);
// The token from "Bearer TOKEN", else from the Cookie header's px_token; "" when neither.
std::string PresentedToken(std::string_view authorization, std::string_view cookie);
bool IsStateChanging(std::string_view method);

struct RequestFacts {
  std::string method;
  std::string path;
  std::string remote_address;
  std::string host;           // Host header
  std::string origin;         // Origin header; "" when absent
  std::string fetch_site;     // Sec-Fetch-Site header; "" when absent
  std::string authorization;  // Authorization header
  std::string cookie;         // Cookie header
};

struct AccessPolicy {
  std::string token;          // the access token (access_token.h)
  bool token_always = false;  // http.token_required == "always"
};

struct AccessDecision {
  int status = 0;      // 0: allowed; else 401 or 403
  std::string reason;  // for the reply and the log
  bool Allowed() const { return status == 0; }
};

AccessDecision DecideAccess(const RequestFacts& request, const AccessPolicy& policy);

// The px_token cookie that logs a browser in: HttpOnly, SameSite=Strict, for the whole site.
std::string LoginCookie(const std::string& token);

}  // namespace px::device
