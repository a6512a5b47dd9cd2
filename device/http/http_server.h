// The camera's web app and JSON API inside parallaxd (cpp-httplib): the gallery, the button with
// live progress, a job's details and settings as static pages, and /api/... for them and for
// scripts (openapi.yaml documents it). Every request first passes the guards in this order:
// connections in flight (503), the client's request rate (429), access and CSRF
// (request_guard.h: 401, 403); bodies over the limit get 413, headers over 8 kB get 431 from the
// library. The server never stops the daemon: a port that cannot be bound is an error from Start
// that parallaxd logs, and the button and control socket keep working.
#pragma once

#include <atomic>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include "device/config.h"
#include "device/http/event_hub.h"
#include "device/http/rate_limiter.h"
#include "device/http/request_guard.h"
#include "device/preview/preview_session.h"
#include "pipeline/core/status.h"

namespace httplib {
class Server;
}

namespace px::device {

class Daemon;

struct HttpServerOptions {
  std::string host = "127.0.0.1";
  int port = 8080;                   // 0: any free port (port() tells which)
  std::filesystem::path token_path;  // the access token's file (access_token.h)
  bool token_always = false;
  size_t max_body_bytes = 256 * 1024;
  int max_requests_in_flight = 64;
  double requests_per_s = 50;
  int max_event_streams = 8;
  PreviewOptions preview;  // authoring's live previews (device/preview); binary "" = off
};

// From the config's http section (the token lives in the store's root); nullopt when
// http.listen is "" (no web app wanted).
StatusOr<std::optional<HttpServerOptions>> HttpServerOptionsFromConfig(const HttpSettings& http,
                                                                       const std::filesystem::path& storage_root);

class HttpServer {
 public:
  // Subscribes to the daemon's events, so construct before Daemon::Start.
  HttpServer(HttpServerOptions options, Daemon* daemon);
  ~HttpServer();  // Stop()

  // Loads or makes the access token, binds and starts serving on a thread of its own. Errors
  // name the address ("http: cannot listen on 0.0.0.0:80: ...").
  Status Start();
  // Ends event streams, stops accepting, waits for requests in progress.
  void Stop();

  int port() const { return port_; }
  std::string Url() const;  // http://HOST:PORT/
  const std::string& token() const { return policy_.token; }

 private:
  void InstallGuards();

  HttpServerOptions options_;
  Daemon* daemon_;
  AccessPolicy policy_;
  RateLimiter rate_limiter_;
  std::shared_ptr<EventHub> events_;
  std::shared_ptr<std::atomic<int>> in_flight_;  // connections queued or being served
  std::shared_ptr<std::atomic<int>> event_streams_;
  std::shared_ptr<PreviewSessions> previews_;
  std::unique_ptr<httplib::Server> server_;
  std::thread thread_;
  int port_ = 0;
};

}  // namespace px::device
