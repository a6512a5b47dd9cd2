// parallaxd: the capture daemon. Parses flags and the config, builds the daemon, runs it until
// "quit", SIGINT/SIGTERM, or (with --stdin-trigger) the end of stdin. Logs go to stderr; stdout
// carries one `clip: <absolute path>` line per finished clip, for scripts.
#include <pthread.h>
#include <signal.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "device/config.h"
#include "device/daemon_factory.h"
#include "device/http/access_token.h"
#include "device/http/http_server.h"
#include "device/preview/preview_protocol.h"
#include "device/preview/preview_worker.h"
#include "device/systemd/systemd_notifier.h"
#include "device/worker/worker_main.h"
#include "device/worker/worker_protocol.h"
#include "pipeline/core/log.h"

namespace {

using px::device::DaemonConfig;

int Fail(const px::Status& status) {
  std::cerr << "parallaxd: " << status.ToString() << "\n";
  return status.code() == px::StatusCode::kInvalidArgument ? 2 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  // A job's worker process (device/worker), started by the daemon itself; not for users.
  if (argc == 4 && std::string(argv[1]) == px::device::kJobWorkerFlag && std::string(argv[2]) == "--parent") {
    const int code = px::device::RunJobWorker(static_cast<pid_t>(std::atoll(argv[3])));
    spdlog::apply_all([](const std::shared_ptr<spdlog::logger>& logger) { logger->flush(); });
    std::fflush(nullptr);
    std::_Exit(code);  // skip static destructors: the pipeline's thread pools need no orderly end
  }
  // An authoring session's preview worker (device/preview), started by the daemon itself.
  if (argc == 4 && std::string(argv[1]) == px::device::kPreviewWorkerFlag && std::string(argv[2]) == "--parent") {
    const int code = px::device::RunPreviewWorker(static_cast<pid_t>(std::atoll(argv[3])));
    spdlog::apply_all([](const std::shared_ptr<spdlog::logger>& logger) { logger->flush(); });
    std::fflush(nullptr);
    std::_Exit(code);
  }
  CLI::App app{"parallaxd: turns each button press into a capture and a 3D pan & scan clip"};
  std::string config_path;
  bool print_config = false;
  px::device::DaemonRunFlags flags;
  std::string root;
  std::string socket;
  std::string log_levels;
  std::string http_listen;
  bool print_token = false;
  app.add_option("--config", config_path, "config file (JSON); else $PARALLAX_CONFIG; else built-in defaults");
  app.add_flag("--print-config", print_config, "print the effective config as JSON and exit");
  app.add_flag("--stdin-trigger",
               flags.stdin_trigger,
               "each line on stdin is a button press; end of input stops after the queue drains");
  app.add_flag("--exit-when-idle",
               flags.exit_when_idle,
               "exit once nothing is queued (after resuming leftover jobs; with --stdin-trigger, after EOF)");
  auto* root_option = app.add_option("--root", root, "override storage.root");
  auto* socket_option = app.add_option("--socket", socket, "override control.socket (\"\" disables the socket)");
  auto* http_option =
      app.add_option("--http", http_listen, "override http.listen, HOST:PORT (\"\" disables the web app)");
  app.add_flag(
      "--print-token", print_token, "print the web app's access token (made on first use, kept in the store) and exit");
  auto* log_option = app.add_option("--log", log_levels, "override log.levels, e.g. info or info,device=debug");
  CLI11_PARSE(app, argc, argv);

  auto resolved = px::device::ResolveDaemonConfig(config_path, std::getenv("PARALLAX_CONFIG"));
  if (!resolved.ok()) return Fail(resolved.status());
  DaemonConfig config = resolved->config;
  // Command-line overrides apply last.
  if (root_option->count() > 0) config.storage.root = root;
  if (socket_option->count() > 0) config.control_socket = socket;
  if (log_option->count() > 0) config.log_levels = log_levels;
  if (http_option->count() > 0) config.http.listen = http_listen;
  if (px::Status valid = config.Validate(); !valid.ok()) return Fail(valid);
  if (print_config) {
    std::cout << px::device::DaemonConfigToJson(config).dump(2) << std::endl;
    return 0;
  }
  if (print_token) {
    std::error_code ec;
    std::filesystem::create_directories(config.storage.root, ec);
    auto token = px::device::LoadOrCreateAccessToken(std::filesystem::absolute(config.storage.root) / "http_token");
    if (!token.ok()) return Fail(token.status());
    std::cout << *token << std::endl;
    return 0;
  }
  if (px::Status levels = px::SetLogLevels(config.log_levels); !levels.ok()) {
    return Fail(levels.WithContext("log.levels"));
  }
  px::Logger("device")->info("config from {}", resolved->origin);

  // Signals are taken by one thread with sigwait; every other thread inherits the blocked mask.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  // Under systemd (Type=notify): READY/STATUS/STOPPING, and watchdog pings from the daemon's loop.
  auto systemd = px::device::SystemdNotifier::FromEnvironment();
  if (!systemd.ok()) return Fail(systemd.status());
  if (*systemd) {
    if (auto pinger = (*systemd)->MakeWatchdogPinger()) flags.loop_inputs.push_back(pinger);
  }
  auto daemon = px::device::BuildDaemon(config, flags);
  if (!daemon.ok()) return Fail(daemon.status());
  std::mutex stdout_mutex;
  (*daemon)->SetClipListener([&stdout_mutex](const std::filesystem::path& clip) {
    std::lock_guard<std::mutex> lock(stdout_mutex);
    std::cout << "clip: " << clip.string() << std::endl;
  });
  if (*systemd) {
    (*daemon)->SetStateListener([notifier = systemd->get()](const std::string& state, bool stopping) {
      notifier->ReportState(state, stopping);
    });
  }
  auto http_options = px::device::HttpServerOptionsFromConfig(config.http, config.storage.root);
  if (!http_options.ok()) return Fail(http_options.status());
  std::unique_ptr<px::device::HttpServer> http;
  if (*http_options) {
    (*http_options)->preview.binary = px::device::WorkerBinary(flags);
    (*http_options)->preview.config = px::device::DaemonConfigToJson(config);
    (*http_options)->preview.memory_limit_bytes = px::device::WorkerMemoryLimit(config);
    http = std::make_unique<px::device::HttpServer>(**http_options, daemon->get());
  }
  if (px::Status started = (*daemon)->Start(); !started.ok()) return Fail(started);
  // The web app is a convenience beside the button and the control socket: a port already taken
  // is logged, and the camera works on without it.
  if (http) {
    if (px::Status serving = http->Start(); !serving.ok()) {
      px::Logger("device")->error("{}; the web app is off, the button and control socket work", serving.ToString());
      http.reset();
    }
  }
  if (*systemd) (*systemd)->Ready();  // the control socket listens now

  std::atomic<bool> finished{false};
  std::thread signal_thread([&] {
    while (true) {
      int signal = 0;
      if (sigwait(&signals, &signal) != 0) continue;
      if (finished.load()) return;
      px::Logger("device")->info("signal {}: stopping after the current step; saved jobs resume at the next start",
                                 signal == SIGINT ? "SIGINT" : "SIGTERM");
      (*daemon)->RequestStop(/*drain=*/false);
    }
  });
  (*daemon)->Wait();
  if (http) http->Stop();
  if (*systemd) (*systemd)->Stopping();
  finished = true;
  pthread_kill(signal_thread.native_handle(), SIGTERM);  // wakes the sigwait so the thread ends
  signal_thread.join();
  return 0;
}
