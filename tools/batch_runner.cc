#include "tools/batch_runner.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "capture/sha256.h"
#include "device/storage/storage_layout.h"
#include "pipeline/core/log.h"
#include "pipeline/io/durable_file.h"

extern char** environ;

namespace px::cli {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

std::atomic<int> g_stop_signal{0};
void OnStopSignal(int signal) { g_stop_signal.store(signal); }

// SIGINT and SIGTERM set g_stop_signal while it lives; the previous handlers come back after.
class StopSignals {
 public:
  StopSignals() {
    g_stop_signal.store(0);
    struct sigaction action {};
    action.sa_handler = OnStopSignal;
    sigemptyset(&action.sa_mask);
    sigaction(SIGINT, &action, &old_int_);
    sigaction(SIGTERM, &action, &old_term_);
  }
  ~StopSignals() {
    sigaction(SIGINT, &old_int_, nullptr);
    sigaction(SIGTERM, &old_term_, nullptr);
  }
  int signal() const { return g_stop_signal.load(); }

 private:
  struct sigaction old_int_ {};
  struct sigaction old_term_ {};
};

std::string SafeName(const fs::path& path) {
  fs::path base = path;
  if (!base.has_filename()) base = base.parent_path();  // "rec/" names it "rec"
  std::string name = fs::is_directory(base) ? base.filename().string() : base.stem().string();
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_') c = '_';
  }
  return name.empty() ? std::string("input") : name;
}

std::string FileStamp(const fs::path& path) {
  std::error_code ec;
  const auto size = fs::file_size(path, ec);
  const auto time = fs::last_write_time(path, ec).time_since_epoch().count();
  return std::to_string(ec ? 0 : size) + " " + std::to_string(time);
}

std::string Fingerprint(const BatchInput& input, const BatchOptions& options) {
  const std::string text = options.options_fingerprint + "\n" + InputIdentity(input.path);
  return capture::Sha256HexOfText(text);
}

struct Paths {
  fs::path clip, report, log, done;
};

Paths PathsFor(const BatchInput& input, const BatchOptions& options) {
  Paths paths;
  paths.clip = options.output_dir / (input.name + options.clip_extension);
  paths.report = device::ClipReportPathFor(paths.clip);
  paths.log = options.output_dir / "batch" / (input.name + ".log");
  paths.done = options.output_dir / "batch" / (input.name + ".done.json");
  return paths;
}

// What the clip's own report says of the move and of what went wrong on the way.
void ReadClipReport(const fs::path& report_path, BatchEntry& entry) {
  StatusOr<std::string> text = ReadFileToString(report_path);
  if (!text.ok()) return;
  const nlohmann::json report = nlohmann::json::parse(*text, nullptr, /*allow_exceptions=*/false);
  if (!report.is_object()) return;
  const nlohmann::json& path = report.value("camera_path", nlohmann::json::object());
  entry.kind = path.value("kind", "");
  entry.move = path.value("move", "");
  entry.warnings = report.value("warnings", std::vector<std::string>{});
}

// True when the input's clip was made before from the same input with the same options.
bool AlreadyDone(const BatchInput& input,
                 const BatchOptions& options,
                 const std::string& fingerprint,
                 BatchEntry& entry) {
  const Paths paths = PathsFor(input, options);
  std::error_code ec;
  if (!fs::exists(paths.clip, ec) || !fs::exists(paths.report, ec)) return false;
  StatusOr<std::string> text = ReadFileToString(paths.done);
  if (!text.ok()) return false;
  const nlohmann::json done = nlohmann::json::parse(*text, nullptr, /*allow_exceptions=*/false);
  if (!done.is_object() || done.value("fingerprint", "") != fingerprint) return false;
  entry.seconds = done.value("seconds", 0.0);
  return true;
}

// The last error the clip process logged (spdlog's "E [module] ..." lines; else its last line, as
// a command-line parser writes it), and how it ended when a signal killed it.
std::string FailureReason(const fs::path& log, int wait_status) {
  std::ifstream in(log);
  std::string line, last_error, last_line;
  while (std::getline(in, line)) {
    const size_t at = line.find(" E [");
    if (at != std::string::npos) last_error = line.substr(at + 3);
    if (line.find_first_not_of(" \t") != std::string::npos) last_line = line;
  }
  if (last_error.empty()) last_error = last_line;
  if (WIFSIGNALED(wait_status)) {
    const int signal = WTERMSIG(wait_status);
    const std::string how = "killed by signal " + std::to_string(signal) + " (" + strsignal(signal) + ")";
    return last_error.empty() ? how : last_error + " (" + how + ")";
  }
  const std::string status = "exit status " + std::to_string(WIFEXITED(wait_status) ? WEXITSTATUS(wait_status) : -1);
  return last_error.empty() ? status : last_error;
}

StatusOr<pid_t> SpawnClip(const BatchInput& input, const BatchOptions& options, const Paths& paths) {
  std::vector<std::string> args = {options.parallax.string(),
                                   "clip",
                                   input.path.string(),
                                   "-o",
                                   options.clip_extension.empty() ? paths.clip.string() + "/" : paths.clip.string(),
                                   "-q"};
  args.insert(args.end(), options.clip_flags.begin(), options.clip_flags.end());
  std::vector<char*> argv;
  for (std::string& arg : args) argv.push_back(arg.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, paths.log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  pid_t pid = 0;
  const int error = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (error != 0) {
    return InternalError("cannot start " + options.parallax.string() + " for " + input.path.string() + ": " +
                         std::strerror(error));
  }
  return pid;
}

// What a clip process that did not finish left in the output folder: its temporaries
// (TemporaryPathFor: .<name>....tmp-<pid>-<n>...), found by its pid, so a batch sharing the
// folder with others (an array job's tasks on other machines) touches only its own.
void RemoveTemporariesOf(pid_t pid, const BatchInput& input, const BatchOptions& options) {
  std::error_code ec;
  const std::string prefix = "." + input.name;
  const std::string owner = ".tmp-" + std::to_string(pid) + "-";
  for (const fs::directory_entry& entry : fs::directory_iterator(options.output_dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(prefix, 0) == 0 && name.find(owner) != std::string::npos && IsTemporaryName(name)) {
      fs::remove_all(entry.path(), ec);
    }
  }
}

struct Running {
  size_t index = 0;
  pid_t pid = 0;
  Clock::time_point start;
};

double SecondsSince(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

Status WriteSummary(const BatchSummary& summary, const BatchOptions& options) {
  return WriteFileAtomically(options.SummaryPath(), BatchSummaryToJson(summary, options).dump(2) + "\n");
}

void Announce(const BatchOptions& options, size_t index, size_t total, const BatchEntry& entry) {
  if (options.quiet) return;
  auto log = Logger("batch");
  const std::string where = "[" + std::to_string(index + 1) + "/" + std::to_string(total) + "] " + entry.name;
  if (entry.status == "done") {
    log->info("{}: done in {:.1f} s ({} {}, {} warning(s))",
              where,
              entry.seconds,
              entry.kind,
              entry.move,
              entry.warnings.size());
  } else if (entry.status == "skipped") {
    log->info("{}: skipped, made before from the same input with the same options", where);
  } else {
    log->error("{}: {}: {} (log {})", where, entry.status, entry.error, entry.log);
  }
}

}  // namespace

fs::path BatchOptions::SummaryPath() const { return summary_path.empty() ? output_dir / "batch.json" : summary_path; }

int BatchSummary::Count(const std::string& status) const {
  return static_cast<int>(
      std::count_if(entries.begin(), entries.end(), [&](const BatchEntry& e) { return e.status == status; }));
}

std::vector<BatchInput> NameBatchInputs(const std::vector<fs::path>& paths) {
  std::vector<BatchInput> inputs;
  std::map<std::string, int> uses;
  for (const fs::path& path : paths) {
    std::string name = SafeName(path);
    const int use = ++uses[name];
    if (use > 1) name += "-" + std::to_string(use);
    inputs.push_back({path, name});
  }
  return inputs;
}

std::string InputIdentity(const fs::path& input) {
  std::error_code ec;
  std::ostringstream identity;
  identity << fs::absolute(input, ec).lexically_normal().string() << "\n";
  if (fs::is_directory(input, ec)) {
    if (StatusOr<std::string> manifest = ReadFileToString(input / "manifest.json"); manifest.ok()) {
      identity << "recording " << capture::Sha256HexOfText(*manifest);
      return identity.str();
    }
    std::vector<std::string> files;
    for (const fs::directory_entry& entry : fs::directory_iterator(input, ec)) {
      if (entry.is_regular_file(ec)) files.push_back(entry.path().filename().string() + " " + FileStamp(entry.path()));
    }
    std::sort(files.begin(), files.end());
    for (const std::string& file : files) identity << file << "\n";
    return identity.str();
  }
  identity << "file " << FileStamp(input);
  return identity.str();
}

StatusOr<BatchSummary> RunBatch(const std::vector<BatchInput>& inputs, const BatchOptions& options) {
  std::error_code ec;
  fs::create_directories(options.output_dir / "batch", ec);
  if (ec) return UnavailableError("cannot make " + (options.output_dir / "batch").string() + ": " + ec.message());
  const auto start = Clock::now();
  BatchSummary summary;
  std::vector<std::string> fingerprints;
  for (const BatchInput& input : inputs) {
    BatchEntry entry;
    entry.input = input.path.string();
    entry.name = input.name;
    entry.log = PathsFor(input, options).log.string();
    summary.entries.push_back(entry);
    fingerprints.push_back(Fingerprint(input, options));
  }
  StopSignals stop;
  std::vector<Running> running;
  size_t next = 0;
  const size_t jobs = static_cast<size_t>(std::max(1, options.jobs));
  Status status = OkStatus();
  while ((next < inputs.size() || !running.empty()) && status.ok()) {
    if (stop.signal() != 0) break;
    // Start inputs until `jobs` run; those made before are skipped on the way.
    while (next < inputs.size() && running.size() < jobs) {
      const size_t index = next++;
      BatchEntry& entry = summary.entries[index];
      const Paths paths = PathsFor(inputs[index], options);
      if (AlreadyDone(inputs[index], options, fingerprints[index], entry)) {
        entry.status = "skipped";
        entry.clip = paths.clip.string();
        ReadClipReport(paths.report, entry);
        Announce(options, index, inputs.size(), entry);
        continue;
      }
      fs::remove(paths.done, ec);  // an older clip of this input no longer counts as done
      StatusOr<pid_t> pid = SpawnClip(inputs[index], options, paths);
      if (!pid.ok()) {
        status = pid.status();
        break;
      }
      running.push_back({index, *pid, Clock::now()});
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    for (auto it = running.begin(); it != running.end();) {
      int wait_status = 0;
      if (::waitpid(it->pid, &wait_status, WNOHANG) != it->pid) {
        ++it;
        continue;
      }
      BatchEntry& entry = summary.entries[it->index];
      const Paths paths = PathsFor(inputs[it->index], options);
      entry.seconds = SecondsSince(it->start);
      if (stop.signal() != 0 && !(WIFEXITED(wait_status) && WEXITSTATUS(wait_status) == 0)) {
        entry.status = "interrupted";
      } else if (WIFEXITED(wait_status) && WEXITSTATUS(wait_status) == 0) {
        entry.status = "done";
        entry.clip = paths.clip.string();
        ReadClipReport(paths.report, entry);
        const nlohmann::json done = {{"input", entry.input},
                                     {"fingerprint", fingerprints[it->index]},
                                     {"clip", entry.clip},
                                     {"seconds", entry.seconds}};
        if (Status written = WriteFileAtomically(paths.done, done.dump(2) + "\n"); !written.ok()) status = written;
      } else {
        entry.status = "failed";
        entry.error = FailureReason(paths.log, wait_status);
      }
      if (entry.status != "done") RemoveTemporariesOf(it->pid, inputs[it->index], options);
      Announce(options, it->index, inputs.size(), entry);
      it = running.erase(it);
      summary.seconds = SecondsSince(start);
      if (Status written = WriteSummary(summary, options); !written.ok() && status.ok()) status = written;
    }
  }
  // Stopped (a signal, or an error of the batch itself): the children stop too, and are reaped.
  for (const Running& child : running) ::kill(child.pid, SIGTERM);
  for (const Running& child : running) {
    int wait_status = 0;
    ::waitpid(child.pid, &wait_status, 0);
    RemoveTemporariesOf(child.pid, inputs[child.index], options);
    BatchEntry& entry = summary.entries[child.index];
    entry.status = "interrupted";
    entry.seconds = SecondsSince(child.start);
  }
  summary.interrupted = stop.signal() != 0;
  summary.seconds = SecondsSince(start);
  if (!status.ok()) return status;
  PX_RETURN_IF_ERROR(WriteSummary(summary, options));
  return summary;
}

nlohmann::json BatchSummaryToJson(const BatchSummary& summary, const BatchOptions& options) {
  nlohmann::json entries = nlohmann::json::array();
  for (const BatchEntry& e : summary.entries) {
    nlohmann::json j = {{"input", e.input}, {"name", e.name}, {"status", e.status.empty() ? "pending" : e.status}};
    if (!e.clip.empty()) j["clip"] = e.clip;
    if (!e.kind.empty()) j["mode"] = {{"kind", e.kind}, {"move", e.move}};
    if (e.seconds > 0) j["seconds"] = e.seconds;
    if (!e.status.empty() && e.status != "interrupted") j["warnings"] = e.warnings;
    if (!e.error.empty()) j["error"] = e.error;
    j["log"] = e.log;
    entries.push_back(j);
  }
  return {{"format", "parallax-batch"},
          {"output", options.output_dir.string()},
          {"clip_flags", options.clip_flags},
          {"jobs", options.jobs},
          {"inputs", summary.entries.size()},
          {"done", summary.Count("done")},
          {"skipped", summary.Count("skipped")},
          {"failed", summary.Count("failed")},
          {"interrupted", summary.interrupted},
          {"seconds", summary.seconds},
          {"entries", entries}};
}

}  // namespace px::cli
