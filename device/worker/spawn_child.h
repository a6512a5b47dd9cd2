// Starting the daemon's child processes (a job's worker, an authoring session's preview worker):
// the daemon's own binary with a flag, so nothing the pipeline does can take the daemon down.
#pragma once

#include <sys/types.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "pipeline/core/status.h"

namespace px::device {

// Starts `binary flag --parent <this pid>` with each (child fd, our fd) pair in `fds` dup2'ed into
// place and its stdout on our stderr (the daemon's stdout carries "clip:" lines for scripts). In
// its own process group (a terminal's ^C reaches the daemon, which stops its children), with no
// signal blocked (the daemon blocks SIGINT and SIGTERM for its sigwait thread) and the signals
// the daemon handles back at their defaults.
StatusOr<pid_t> SpawnDaemonChild(const std::filesystem::path& binary,
                                 const char* flag,
                                 const std::vector<std::pair<int, int>>& fds);

// The resident memory of a live child (its VmRSS); 0 when it cannot be read (the process is gone).
uint64_t ResidentBytes(pid_t pid);

// "12 MB", rounded.
std::string MegaBytes(uint64_t bytes);

}  // namespace px::device
