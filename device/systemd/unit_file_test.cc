// device/systemd/parallaxd.service: the directives the daemon relies on are there, and
// `systemd-analyze verify` accepts the unit (with ExecStart pointed at the parallaxd just built)
// without a single complaint. Skips with a message where systemd-analyze is not installed.
#include <gtest/gtest.h>

#include <cstdio>
#include <regex>

#include "pipeline/io/durable_file.h"
#include "tests/testing/temp_dir.h"

namespace px::device {
namespace {

namespace fs = std::filesystem;

std::string Unit() {
  auto text = ReadFileToString(fs::path(PX_SOURCE_DIR) / "device/systemd/parallaxd.service");
  EXPECT_TRUE(text.ok()) << text.status().ToString();
  return text.ok() ? *text : "";
}

struct ShellRun {
  int exit_code = -1;
  std::string output;
};

ShellRun RunShell(const std::string& command) {
  ShellRun run;
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return run;
  char buffer[4096];
  size_t n;
  while ((n = fread(buffer, 1, sizeof(buffer), pipe)) > 0) run.output.append(buffer, n);
  const int status = pclose(pipe);
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return run;
}

std::string SystemdAnalyze() {
  for (const char* path : {"/usr/bin/systemd-analyze", "/bin/systemd-analyze"}) {
    if (::access(path, X_OK) == 0) return path;
  }
  return "";
}

// Verifies `unit` as a file named parallaxd.service with ExecStart on the built parallaxd.
ShellRun Verify(const std::string& analyze, std::string unit, const fs::path& dir) {
  unit = std::regex_replace(unit, std::regex("/usr/local/bin/parallaxd"), std::string(PX_BINARY_DIR) + "/parallaxd");
  const fs::path file = dir / "parallaxd.service";
  EXPECT_TRUE(WriteFileAtomically(file, unit).ok());
  return RunShell("timeout 60 " + analyze + " verify " + file.string());
}

TEST(UnitFile, HasTheDirectivesTheDaemonReliesOn) {
  const std::string unit = Unit();
  for (const char* line : {"Type=notify",
                           "NotifyAccess=main",
                           "WatchdogSec=30",
                           "Restart=on-failure",
                           "ExecStart=/usr/local/bin/parallaxd --config /etc/parallax/parallaxd.json",
                           "StateDirectory=parallax",
                           "RuntimeDirectory=parallax",
                           "ProtectSystem=strict",
                           "ReadWritePaths=/var/lib/parallax /run/parallax",
                           "NoNewPrivileges=yes",
                           "WantedBy=multi-user.target"}) {
    EXPECT_TRUE(std::regex_search(unit, std::regex("(^|\n)" + std::string(line) + "\n"))) << "missing: " << line;
  }
}

TEST(UnitFile, SystemdAnalyzeVerifyAcceptsIt) {
  const std::string analyze = SystemdAnalyze();
  if (analyze.empty()) GTEST_SKIP() << "systemd-analyze is not installed on this machine (package systemd)";
  px::testing::TempDir dir;
  ShellRun run = Verify(analyze, Unit(), dir.path());
  EXPECT_EQ(run.exit_code, 0) << run.output;
  // Warnings about a unit do not change the exit status; they all name the file.
  EXPECT_EQ(run.output.find("parallaxd.service"), std::string::npos) << run.output;

  // The check can fail: a bad value in a copy is reported.
  ShellRun bad =
      Verify(analyze, std::regex_replace(Unit(), std::regex("WatchdogSec=30"), "WatchdogSec=thirty"), dir.path());
  EXPECT_NE(bad.output.find("parallaxd.service"), std::string::npos) << bad.output;
}

}  // namespace
}  // namespace px::device
