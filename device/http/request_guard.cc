#include "device/http/request_guard.h"

#include <arpa/inet.h>

#include <cctype>

#include "device/http/access_token.h"

namespace px::device {

namespace {

constexpr std::string_view kCookieName = "px_token";

std::string_view Trim(std::string_view text) {
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.front()))) text.remove_prefix(1);
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back()))) text.remove_suffix(1);
  return text;
}

bool OpenToAll(std::string_view method, std::string_view path) {
  if (method == "GET" || method == "HEAD")
    return path == "/login.html" || path == "/login.js" || path == "/style.css" || path == "/favicon.svg";
  return method == "POST" && path == "/api/login";
}

}  // namespace

bool IsLoopbackAddress(std::string_view address) {
  const std::string text(address);
  in_addr v4{};
  if (inet_pton(AF_INET, text.c_str(), &v4) == 1) return (ntohl(v4.s_addr) >> 24) == 127;
  in6_addr v6{};
  if (inet_pton(AF_INET6, text.c_str(), &v6) != 1) return false;
  if (IN6_IS_ADDR_LOOPBACK(&v6)) return true;
  // ::ffff:127.x.y.z, an IPv4 loopback peer on a dual-stack socket.
  return IN6_IS_ADDR_V4MAPPED(&v6) && v6.s6_addr[12] == 127;
}

bool IsLoopbackHost(std::string_view host_header) {
  std::string_view host = Trim(host_header);
  if (!host.empty() && host.front() == '[') {
    const size_t close = host.find(']');
    if (close == std::string_view::npos) return false;
    host = host.substr(1, close - 1);
  } else if (const size_t colon = host.rfind(':'); colon != std::string_view::npos) {
    host = host.substr(0, colon);
  }
  std::string lower;
  for (char c : host) lower += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return lower == "localhost" || IsLoopbackAddress(lower);
}

std::string PresentedToken(std::string_view authorization, std::string_view cookie) {
  const std::string_view auth = Trim(authorization);
  constexpr std::string_view kBearer = "Bearer ";
  if (auth.size() > kBearer.size() && auth.substr(0, kBearer.size()) == kBearer) {
    return std::string(Trim(auth.substr(kBearer.size())));
  }
  std::string_view rest = cookie;
  while (!rest.empty()) {
    const size_t semicolon = rest.find(';');
    const std::string_view pair = Trim(rest.substr(0, semicolon));
    rest = semicolon == std::string_view::npos ? std::string_view() : rest.substr(semicolon + 1);
    const size_t equals = pair.find('=');
    if (equals != std::string_view::npos && Trim(pair.substr(0, equals)) == kCookieName) {
      return std::string(Trim(pair.substr(equals + 1)));
    }
  }
  return "";
}

bool IsStateChanging(std::string_view method) {
  return method == "POST" || method == "PUT" || method == "PATCH" || method == "DELETE";
}

AccessDecision DecideAccess(const RequestFacts& request, const AccessPolicy& policy) {
  if (IsStateChanging(request.method)) {
    if (request.fetch_site == "cross-site") return {403, "cross-site request refused"};
    if (!request.origin.empty() && request.origin != "http://" + request.host &&
        request.origin != "https://" + request.host) {
      return {403, "request from origin " + request.origin + " refused: not this server's own"};
    }
  }
  if (OpenToAll(request.method, request.path)) return {};
  const bool at_the_device = IsLoopbackAddress(request.remote_address) && IsLoopbackHost(request.host);
  if (at_the_device && !policy.token_always) return {};
  const std::string presented = PresentedToken(request.authorization, request.cookie);
  if (presented.empty()) return {401, "access token required (log in, or send Authorization: Bearer TOKEN)"};
  if (!TokensEqual(presented, policy.token)) return {401, "wrong access token"};
  return {};
}

std::string LoginCookie(const std::string& token) {
  return std::string(kCookieName) + "=" + token + "; Path=/; HttpOnly; SameSite=Strict; Max-Age=31536000";
}

}  // namespace px::device
