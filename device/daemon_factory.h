// Builds the daemon a DaemonConfig describes: the source from the registry, the clip job from
// the clip settings. parallaxd's main() is flags + this + Run.
#pragma once

#include <filesystem>
#include <memory>
#include <vector>

#include "device/clip_job.h"
#include "device/config.h"
#include "device/daemon.h"

namespace px::device {

struct DaemonRunFlags {
  bool stdin_trigger = false;   // each line on stdin is a press; EOF drains and stops
  bool exit_when_idle = false;  // stop once nothing is queued (see DaemonOptions)
  // More inputs for the daemon's loop, e.g. parallaxd's systemd watchdog pinger.
  std::vector<std::shared_ptr<LoopInput>> loop_inputs;
  // The executable each job's worker process runs (it must serve --job-worker); "" = this one.
  std::filesystem::path worker_binary;
};

// The executable the daemon's children run (job and preview workers): flags.worker_binary, or
// this one.
std::filesystem::path WorkerBinary(const DaemonRunFlags& flags);
// The resident memory at which a worker process (a job's or a live preview's) is killed:
// worker.memory_limit_mb, or three quarters of the machine's memory when it is 0.
uint64_t WorkerMemoryLimit(const DaemonConfig& config);

// The pipeline and encoder options for the config's clip settings. Errors name the field
// ("clip.move: 'spin' is not a known move").
StatusOr<ClipJobOptions> ClipJobOptionsFromConfig(const DaemonConfig& config);

// The daemon's options for a config (storage, socket, timeout) and the run flags.
DaemonOptions DaemonOptionsFromConfig(const DaemonConfig& config, const DaemonRunFlags& flags);

// A JobRunner that runs RunClipJob in this process and logs the pipeline's warnings (what a
// job's worker process runs).
JobRunner MakeClipJobRunner(const ClipJobOptions& options);

// Opens the configured source and assembles the daemon (not started); its jobs run in worker
// processes (worker/worker_runner.h) under the config's worker limits.
StatusOr<std::unique_ptr<Daemon>> BuildDaemon(const DaemonConfig& config, const DaemonRunFlags& flags);

}  // namespace px::device
