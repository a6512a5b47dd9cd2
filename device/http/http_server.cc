#include "device/http/http_server.h"

#include <arpa/inet.h>
#include <httplib.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include <cerrno>
#include <cstring>
#include <nlohmann/json.hpp>

#include "device/daemon.h"
#include "device/http/access_token.h"
#include "device/http/http_api.h"
#include "device/http/web_pages.h"
#include "pipeline/core/log.h"

namespace px::device {

namespace {

constexpr int kWorkerThreads = 16;

// The library's thread pool, counting connections from the moment they are queued until they
// are served, so the guard can refuse work beyond the limit instead of queueing it without end.
class CountingThreadPool : public httplib::TaskQueue {
 public:
  CountingThreadPool(size_t threads, std::shared_ptr<std::atomic<int>> in_flight)
      : pool_(threads), in_flight_(std::move(in_flight)) {}
  void enqueue(std::function<void()> fn) override {
    in_flight_->fetch_add(1);
    pool_.enqueue([fn = std::move(fn), in_flight = in_flight_] {
      fn();
      in_flight->fetch_sub(1);
    });
  }
  void shutdown() override { pool_.shutdown(); }

 private:
  httplib::ThreadPool pool_;
  std::shared_ptr<std::atomic<int>> in_flight_;
};

// Debian's library is built with a listen backlog of 5: a burst of phones (or a page's parallel
// fetches) overflows it, and the kernel drops the overflow's handshakes, which the clients only
// retry after a second or more. Listening again on the same socket widens the queue; the guard
// then answers the burst with pages or 503s instead of silence.
void WidenListenBacklog(int socket, int port) {
  constexpr int kListenBacklog = 512;
  int accepting = 0;
  socklen_t size = sizeof(accepting);
  sockaddr_storage address{};
  socklen_t address_size = sizeof(address);
  if (socket < 0 || getsockopt(socket, SOL_SOCKET, SO_ACCEPTCONN, &accepting, &size) != 0 || !accepting ||
      getsockname(socket, reinterpret_cast<sockaddr*>(&address), &address_size) != 0) {
    Logger("http")->warn("http: the listening socket was not found; the library's backlog of 5 stays");
    return;
  }
  const int bound_port = address.ss_family == AF_INET6 ? ntohs(reinterpret_cast<sockaddr_in6*>(&address)->sin6_port)
                                                       : ntohs(reinterpret_cast<sockaddr_in*>(&address)->sin_port);
  if (bound_port != port) {
    Logger("http")->warn(
        "http: socket {} is on port {}, not {}; the library's backlog of 5 stays", socket, bound_port, port);
  } else if (::listen(socket, kListenBacklog) != 0) {
    Logger("http")->warn("http: could not widen the listen backlog: {}", std::strerror(errno));
  }
}

void Refuse(httplib::Response& res, int status, const std::string& reason) {
  res.status = status;
  res.set_content(nlohmann::json({{"ok", false}, {"error", reason}}).dump(), "application/json");
}

}  // namespace

StatusOr<std::optional<HttpServerOptions>> HttpServerOptionsFromConfig(const HttpSettings& http,
                                                                       const std::filesystem::path& storage_root) {
  if (http.listen.empty()) return std::optional<HttpServerOptions>();
  HttpServerOptions options;
  const size_t colon = http.listen.rfind(':');
  if (colon == std::string::npos || colon == 0) {
    return InvalidArgumentError("http.listen: '" + http.listen + "' is not HOST:PORT");
  }
  options.host = http.listen.substr(0, colon);
  if (options.host.size() > 2 && options.host.front() == '[' && options.host.back() == ']') {
    options.host = options.host.substr(1, options.host.size() - 2);
  }
  options.port = std::stoi(http.listen.substr(colon + 1));
  options.token_path = std::filesystem::absolute(storage_root) / "http_token";
  options.token_always = http.token_required == "always";
  options.max_body_bytes = static_cast<size_t>(http.max_body_kb) * 1024;
  options.max_requests_in_flight = http.max_requests_in_flight;
  options.requests_per_s = http.requests_per_s;
  options.max_event_streams = http.max_event_streams;
  return std::optional<HttpServerOptions>(options);
}

HttpServer::HttpServer(HttpServerOptions options, Daemon* daemon)
    : options_(std::move(options)),
      daemon_(daemon),
      rate_limiter_(options_.requests_per_s),
      events_(std::make_shared<EventHub>()),
      in_flight_(std::make_shared<std::atomic<int>>(0)),
      event_streams_(std::make_shared<std::atomic<int>>(0)),
      previews_(std::make_shared<PreviewSessions>(options_.preview)) {
  policy_.token_always = options_.token_always;
  daemon_->SetEventListener([events = events_](const nlohmann::json& event) { events->Publish(event); });
}

HttpServer::~HttpServer() { Stop(); }

void HttpServer::InstallGuards() {
  server_->set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
    auto log = Logger("http");
    if (in_flight_->load() > options_.max_requests_in_flight) {
      res.set_header("Retry-After", "1");
      Refuse(res, 503, "busy: more than " + std::to_string(options_.max_requests_in_flight) + " requests at once");
      return httplib::Server::HandlerResponse::Handled;
    }
    if (!rate_limiter_.Allow(req.remote_addr)) {
      res.set_header("Retry-After", "1");
      Refuse(res, 429, "too many requests from " + req.remote_addr);
      return httplib::Server::HandlerResponse::Handled;
    }
    RequestFacts facts;
    facts.method = req.method;
    facts.path = req.path;
    facts.remote_address = req.remote_addr;
    facts.host = req.get_header_value("Host");
    facts.origin = req.get_header_value("Origin");
    facts.fetch_site = req.get_header_value("Sec-Fetch-Site");
    facts.authorization = req.get_header_value("Authorization");
    facts.cookie = req.get_header_value("Cookie");
    const AccessDecision access = DecideAccess(facts, policy_);
    if (!access.Allowed()) {
      log->info("{} {} from {}: {} {}", req.method, req.path, req.remote_addr, access.status, access.reason);
      // A browser asking for a page without the token goes to the login page instead.
      if (access.status == 401 && req.method == "GET" && req.path.rfind("/api/", 0) != 0) {
        res.set_redirect("/login.html");
        return httplib::Server::HandlerResponse::Handled;
      }
      Refuse(res, access.status, access.reason);
      return httplib::Server::HandlerResponse::Handled;
    }
    return httplib::Server::HandlerResponse::Unhandled;
  });
  server_->set_post_routing_handler([](const httplib::Request&, httplib::Response& res) {
    // The pages load nothing from elsewhere; say so to the browser.
    res.set_header("Content-Security-Policy",
                   "default-src 'self'; img-src 'self' data: blob:; media-src 'self'; frame-ancestors 'none'");
    res.set_header("X-Content-Type-Options", "nosniff");
    res.set_header("Referrer-Policy", "no-referrer");
  });
  server_->set_exception_handler([](const httplib::Request& req, httplib::Response& res, std::exception_ptr ep) {
    std::string what = "unknown exception";
    try {
      std::rethrow_exception(ep);
    } catch (const std::exception& e) {
      what = e.what();
    } catch (...) {
    }
    Logger("http")->error("{} {}: handler threw: {}", req.method, req.path, what);
    Refuse(res, 500, "internal error: " + what);
  });
  server_->set_error_handler([this](const httplib::Request&, httplib::Response& res) {
    if (!res.body.empty()) return;
    switch (res.status) {
      case 404:
        return Refuse(res, 404, "no such page or API call");
      case 413:
        return Refuse(res, 413, "request body over " + std::to_string(options_.max_body_bytes) + " bytes");
      default:
        return Refuse(res, res.status, "HTTP " + std::to_string(res.status));
    }
  });
}

Status HttpServer::Start() {
  auto log = Logger("http");
  PX_ASSIGN_OR_RETURN(policy_.token, LoadOrCreateAccessToken(options_.token_path));
  server_ = std::make_unique<httplib::Server>();
  server_->new_task_queue = [in_flight = in_flight_] { return new CountingThreadPool(kWorkerThreads, in_flight); };
  server_->set_payload_max_length(options_.max_body_bytes);
  server_->set_read_timeout(5);
  server_->set_write_timeout(10);
  server_->set_keep_alive_timeout(2);
  server_->set_keep_alive_max_count(100);
  // A reply's header and body leave in separate writes: with Nagle's algorithm the body waits for
  // the client's delayed ACK (40 ms), a live preview's whole budget.
  server_->set_tcp_nodelay(true);
  // SO_REUSEADDR only: the library's default adds SO_REUSEPORT, which would let a second daemon
  // bind the same port and share its requests instead of failing.
  auto listening_socket = std::make_shared<std::atomic<int>>(-1);
  server_->set_socket_options([listening_socket](int socket) {
    const int yes = 1;
    setsockopt(socket, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof(yes));
    listening_socket->store(socket);
  });
  InstallGuards();
  ApiContext api;
  api.daemon = daemon_;
  api.events = events_;
  api.event_streams = event_streams_;
  api.max_event_streams = options_.max_event_streams;
  api.token = policy_.token;
  api.listen_host = options_.host;
  api.previews = previews_;
  RegisterApiRoutes(*server_, api);
  RegisterWebPages(*server_, api);

  const std::string address = options_.host + ":" + std::to_string(options_.port);
  if (options_.port == 0) {
    port_ = server_->bind_to_any_port(options_.host);
    if (port_ <= 0) return UnavailableError("http: cannot listen on " + address + ": no port could be bound");
  } else {
    if (!server_->bind_to_port(options_.host, options_.port)) {
      return UnavailableError("http: cannot listen on " + address + ": " + std::strerror(errno) +
                              " (another program on that port? set http.listen)");
    }
    port_ = options_.port;
  }
  WidenListenBacklog(listening_socket->load(), port_);
  thread_ = std::thread([this] { server_->listen_after_bind(); });
  log->info("web app at {} (token required {})",
            Url(),
            options_.token_always ? "always" : "from other hosts; show it with parallaxd --print-token");
  return OkStatus();
}

void HttpServer::Stop() {
  events_->Close();
  if (server_) server_->stop();
  if (thread_.joinable()) thread_.join();
  previews_->CloseAll();
}

std::string HttpServer::Url() const {
  const bool v6 = options_.host.find(':') != std::string::npos;
  return "http://" + (v6 ? "[" + options_.host + "]" : options_.host) + ":" + std::to_string(port_) + "/";
}

}  // namespace px::device
