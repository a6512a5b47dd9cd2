#include "device/process/daemon_process.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstring>
#include <fstream>
#include <map>
#include <thread>

#include "pipeline/io/durable_file.h"

extern char** environ;

namespace px::device {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
constexpr auto kPoll = std::chrono::milliseconds(20);

int DecodeWaitStatus(int status) { return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status); }

}  // namespace

StatusOr<std::unique_ptr<DaemonProcess>> DaemonProcess::Start(const DaemonProcessOptions& options) {
  if (::access(options.binary.c_str(), X_OK) != 0) {
    return InvalidArgumentError("daemon binary " + options.binary.string() + " is not an executable file");
  }
  std::vector<std::string> args = {options.binary.string()};
  args.insert(args.end(), options.args.begin(), options.args.end());
  std::map<std::string, std::string> env;
  for (char** e = environ; *e != nullptr; ++e) {
    const std::string entry = *e;
    const size_t eq = entry.find('=');
    if (eq != std::string::npos) env[entry.substr(0, eq)] = entry.substr(eq + 1);
  }
  for (const auto& [name, value] : options.env) {
    if (value) {
      env[name] = *value;
    } else {
      env.erase(name);
    }
  }
  std::vector<std::string> env_entries;
  for (const auto& [name, value] : env) env_entries.push_back(name + "=" + value);
  std::vector<char*> argv, envp;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  for (auto& e : env_entries) envp.push_back(e.data());
  envp.push_back(nullptr);

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, options.log_path.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  pid_t pid = 0;
  const int err = ::posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&actions);
  if (err != 0) return InternalError("spawn " + options.binary.string() + ": " + std::strerror(err));
  return std::unique_ptr<DaemonProcess>(new DaemonProcess(pid, options.log_path));
}

DaemonProcess::~DaemonProcess() {
  if (running()) (void)KillHard();
}

bool DaemonProcess::running() {
  if (exit_code_) return false;
  int status = 0;
  if (::waitpid(pid_, &status, WNOHANG) == pid_) {
    exit_code_ = DecodeWaitStatus(status);
    return false;
  }
  return true;
}

void DaemonProcess::Signal(int signal) {
  if (running()) ::kill(pid_, signal);
}

StatusOr<int> DaemonProcess::WaitExit(std::chrono::milliseconds timeout) {
  const auto end = Clock::now() + timeout;
  while (running()) {
    if (Clock::now() >= end) {
      (void)KillHard();
      return DeadlineExceededError("parallaxd pid " + std::to_string(pid_) + " did not exit within " +
                                   std::to_string(timeout.count()) + " ms (killed)" + LogTail());
    }
    std::this_thread::sleep_for(kPoll);
  }
  return *exit_code_;
}

Status DaemonProcess::KillHard() {
  if (exit_code_) return OkStatus();
  ::kill(pid_, SIGKILL);
  int status = 0;
  if (::waitpid(pid_, &status, 0) != pid_) {
    return InternalError("waitpid " + std::to_string(pid_) + ": " + std::strerror(errno));
  }
  exit_code_ = DecodeWaitStatus(status);
  return OkStatus();
}

StatusOr<uint64_t> DaemonProcess::RssBytes() const {
  const fs::path status_path = "/proc/" + std::to_string(pid_) + "/status";
  std::ifstream in(status_path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::stoull(line.substr(6)) * 1024;  // "VmRSS:  1234 kB"
  }
  return NotFoundError(status_path.string() + ": no VmRSS line (has the process exited?)");
}

std::string DaemonProcess::Log() const {
  auto text = ReadFileToString(log_path_);
  return text.ok() ? *text : "";
}

std::string DaemonProcess::LogTail() const {
  const std::string log = Log();
  constexpr size_t kTail = 3000;
  return "; log " + log_path_.string() + " ends:\n" + (log.size() > kTail ? log.substr(log.size() - kTail) : log);
}

Status DaemonProcess::WaitForLog(const std::string& text, std::chrono::milliseconds timeout) {
  const auto end = Clock::now() + timeout;
  while (Log().find(text) == std::string::npos) {
    if (!running()) {
      return UnavailableError("parallaxd exited (" + std::to_string(*exit_code_) + ") before logging '" + text + "'" +
                              LogTail());
    }
    if (Clock::now() >= end) {
      return DeadlineExceededError("parallaxd did not log '" + text + "' within " + std::to_string(timeout.count()) +
                                   " ms" + LogTail());
    }
    std::this_thread::sleep_for(kPoll);
  }
  return OkStatus();
}

StatusOr<std::unique_ptr<ControlClient>> DaemonProcess::Connect(const fs::path& socket,
                                                                std::chrono::milliseconds timeout) {
  const auto end = Clock::now() + timeout;
  while (true) {
    auto client = ControlClient::Connect(socket);
    if (client.ok()) return client;
    if (!running()) {
      return UnavailableError("parallaxd exited (" + std::to_string(*exit_code_) + ") before listening on " +
                              socket.string() + LogTail());
    }
    if (Clock::now() >= end) {
      return DeadlineExceededError("parallaxd did not listen on " + socket.string() + " within " +
                                   std::to_string(timeout.count()) + " ms" + LogTail());
    }
    std::this_thread::sleep_for(kPoll);
  }
}

}  // namespace px::device
