// The daemon's job runner: each job's pipeline runs in a child process (the daemon's own binary
// started with --job-worker, worker_main.h), so nothing the pipeline does (a segfault, an abort,
// memory it cannot have) can take the daemon and its button down. The runner supervises it:
// relays its progress, asks it to stop (SIGTERM) when the daemon cancels, and kills it (SIGKILL)
// past its memory or time limit. A worker that dies by a signal, or is killed for a limit, ends
// the job with ABORTED naming the signal or the limit and the stage it was in; the daemon counts
// those (and only those) against the job (daemon.h, DaemonOptions::max_worker_crashes).
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "device/daemon.h"

namespace px::device {

struct WorkerRunnerOptions {
  std::filesystem::path binary;       // an executable that serves --job-worker (parallaxd)
  nlohmann::json config;              // the daemon's effective config, handed to each worker
  uint64_t memory_limit_bytes = 0;    // resident memory at which the worker is killed; 0 = none
  std::chrono::seconds timeout{900};  // one job, start to result
  // After asking a worker to stop, how long it has to return CANCELLED before it is killed.
  std::chrono::milliseconds cancel_grace{10000};
};

// Three quarters of the machine's memory (MemTotal), what worker.memory_limit_mb = 0 means.
uint64_t DefaultWorkerMemoryLimit();

JobRunner MakeWorkerJobRunner(WorkerRunnerOptions options);

}  // namespace px::device
