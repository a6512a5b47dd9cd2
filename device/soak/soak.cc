#include "device/soak/soak.h"

#include <chrono>
#include <deque>
#include <nlohmann/json.hpp>
#include <sstream>

#include "device/process/daemon_process.h"
#include "pipeline/core/log.h"
#include "pipeline/io/durable_file.h"

namespace px::device {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

Status Range(const std::string& field, double value, double low, double high) {
  if (value >= low && value <= high) return OkStatus();
  std::ostringstream out;
  out.precision(12);
  out << "soak " << field << ": " << value << " is not in [" << low << ", " << high << "]";
  return InvalidArgumentError(out.str());
}

uint64_t BytesUnder(const fs::path& root) {
  uint64_t total = 0;
  std::error_code ec;
  for (fs::recursive_directory_iterator it(root, ec), end; !ec && it != end; it.increment(ec)) {
    std::error_code size_ec;
    if (it->is_regular_file(size_ec)) total += it->file_size(size_ec);
  }
  return total;
}

StatusOr<nlohmann::json> Call(ControlClient& client, const std::string& request, std::chrono::milliseconds timeout) {
  PX_ASSIGN_OR_RETURN(std::string reply, client.Call(request, timeout));
  nlohmann::json j = nlohmann::json::parse(reply, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) return DataLossError("reply to " + request + " is not JSON: " + reply);
  return j;
}

}  // namespace

Status SoakOptions::Validate() const {
  if (parallaxd.empty()) return InvalidArgumentError("soak parallaxd: empty (the daemon executable)");
  if (work_dir.empty()) return InvalidArgumentError("soak work_dir: empty");
  PX_RETURN_IF_ERROR(Range("presses", presses, 1, 1000000));
  PX_RETURN_IF_ERROR(Range("tile_width", tile_width, 32, 640));
  PX_RETURN_IF_ERROR(Range("tile_height", tile_height, 24, 480));
  PX_RETURN_IF_ERROR(Range("clip_frames", clip_frames, 1, 300));
  PX_RETURN_IF_ERROR(Range("in_flight", in_flight, 1, 64));
  if (!(quota_mb > 0)) return InvalidArgumentError("soak quota_mb: " + std::to_string(quota_mb) + " is not > 0");
  return Range("progress_every", progress_every, 0, 1000000);
}

std::string SoakReport::ToText() const {
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(1);
  out << "presses: " << presses << "\n"
      << "presses handled: " << handled << "\n"
      << "clips made: " << clips << "\n"
      << "captures lost: " << lost << "\n"
      << "clips evicted by the quota: " << evicted << "\n"
      << "daemon RSS at start: " << rss_start_bytes / 1e6 << " MB (after the first clip)\n"
      << "daemon RSS at end: " << rss_end_bytes / 1e6 << " MB\n"
      << "daemon RSS growth: " << RssGrowthMb() << " MB (" << RssSecondHalfGrowthMb()
      << " MB over the second half of the presses)\n"
      << "daemon RSS peak: " << rss_peak_bytes / 1e6 << " MB\n"
      << "storage at end: " << store_bytes / 1e6 << " MB\n"
      << "time: " << seconds << " s (" << (presses > 0 ? seconds / presses : 0.0) << " s per press)\n"
      << "daemon exit code after quit: " << daemon_exit_code << "\n";
  for (const std::string& failure : failures) out << "failed: " << failure << "\n";
  return out.str();
}

StatusOr<SoakReport> RunSoak(const SoakOptions& options) {
  PX_RETURN_IF_ERROR(options.Validate());
  auto log = Logger("soak");
  const fs::path root = options.work_dir / "store";
  const fs::path socket = options.work_dir / "ctl.sock";
  const fs::path config_path = options.work_dir / "parallaxd.json";
  std::error_code ec;
  fs::create_directories(options.work_dir, ec);
  if (ec) return InvalidArgumentError("soak work_dir " + options.work_dir.string() + ": " + ec.message());
  const nlohmann::json config = {
      {"storage", {{"root", root.string()}, {"min_free_mb", 0}, {"quota_mb", options.quota_mb}}},
      {"control", {{"socket", socket.string()}}},
      {"source", {{"sim", {{"tile_width", options.tile_width}, {"tile_height", options.tile_height}}}}},
      {"clip", {{"duration_s", options.clip_frames / 10.0}, {"fps", 10}, {"preset", "ultrafast"}}},
      {"log", {{"levels", "warn"}}},  // a line per job would make a 1000-press log large
  };
  PX_RETURN_IF_ERROR(WriteFileAtomically(config_path, config.dump(2) + "\n"));

  DaemonProcessOptions process_options;
  process_options.binary = options.parallaxd;
  process_options.args = {"--config", config_path.string()};
  process_options.env = {{"PARALLAX_CONFIG", std::nullopt},
                         {"NOTIFY_SOCKET", std::nullopt},
                         {"WATCHDOG_USEC", std::nullopt},
                         {"PARALLAXD_TEST_PAUSE_AT", std::nullopt}};
  process_options.log_path = options.work_dir / "parallaxd.log";
  PX_ASSIGN_OR_RETURN(std::unique_ptr<DaemonProcess> daemon, DaemonProcess::Start(process_options));
  PX_ASSIGN_OR_RETURN(std::unique_ptr<ControlClient> client, daemon->Connect(socket, 60s));
  log->info("soak: parallaxd pid {} up; {} presses, {}x{} tiles, {}-frame clips, quota {} MB",
            daemon->pid(),
            options.presses,
            options.tile_width,
            options.tile_height,
            options.clip_frames,
            options.quota_mb);

  SoakReport report;
  const auto start = std::chrono::steady_clock::now();
  std::deque<std::string> waiting;
  // Waits for the oldest outstanding job and books its outcome.
  auto finish_oldest = [&]() -> Status {
    const std::string id = waiting.front();
    waiting.pop_front();
    PX_ASSIGN_OR_RETURN(nlohmann::json reply, Call(*client, R"({"cmd":"wait","job":")" + id + R"("})", 600s));
    const nlohmann::json job = reply.value("job", nlohmann::json::object());
    if (reply.value("ok", false) && job.value("state", "") == "done") {
      report.clips++;
    } else {
      report.lost++;
      if (report.failures.size() < 10) {
        report.failures.push_back(id + ": " + (reply.value("ok", false) ? job.value("error", "") : reply.dump()));
      }
    }
    if (auto rss = daemon->RssBytes(); rss.ok()) {
      if (report.rss_start_bytes == 0) report.rss_start_bytes = *rss;
      report.rss_end_bytes = *rss;
      report.rss_peak_bytes = std::max(report.rss_peak_bytes, *rss);
    }
    return OkStatus();
  };
  for (int press = 1; press <= options.presses; ++press) {
    report.presses++;
    PX_ASSIGN_OR_RETURN(nlohmann::json pressed, Call(*client, R"({"cmd":"capture"})", 30s));
    if (pressed.value("ok", false)) {
      report.handled++;
      waiting.push_back(pressed.value("job", ""));
    } else if (report.failures.size() < 10) {
      report.failures.push_back("press " + std::to_string(press) + " refused: " + pressed.dump());
    }
    // The first press alone, so the start RSS is taken after one whole job.
    while (!waiting.empty() && (press == 1 || waiting.size() >= static_cast<size_t>(options.in_flight))) {
      PX_RETURN_IF_ERROR(finish_oldest());
    }
    if (press == (options.presses + 1) / 2) report.rss_half_bytes = report.rss_end_bytes;
    if (options.progress_every > 0 && press % options.progress_every == 0) {
      log->info("soak: {} presses, {} clips, {} lost, RSS {:.1f} MB",
                press,
                report.clips,
                report.lost,
                report.rss_end_bytes / 1e6);
    }
  }
  while (!waiting.empty()) PX_RETURN_IF_ERROR(finish_oldest());
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  PX_ASSIGN_OR_RETURN(nlohmann::json list, Call(*client, R"({"cmd":"list"})", 30s));
  for (const nlohmann::json& job : list.value("jobs", nlohmann::json::array())) {
    if (job.value("note", "").rfind("evicted", 0) == 0) report.evicted++;
  }
  PX_ASSIGN_OR_RETURN(nlohmann::json quit, Call(*client, R"({"cmd":"quit"})", 30s));
  (void)quit;
  client.reset();
  PX_ASSIGN_OR_RETURN(report.daemon_exit_code, daemon->WaitExit(60s));
  report.store_bytes = BytesUnder(root);
  return report;
}

}  // namespace px::device
