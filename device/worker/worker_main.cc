#include "device/worker/worker_main.h"

#include <signal.h>
#include <sys/prctl.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <iterator>
#include <string>

#include "device/config.h"
#include "device/daemon_factory.h"
#include "device/test_pause.h"
#include "device/worker/worker_protocol.h"
#include "device/worker/write_all.h"
#include "pipeline/core/log.h"

namespace px::device {
namespace {

std::atomic<bool> stop_requested{false};

void OnTerm(int) { stop_requested.store(true); }

// One whole line to the daemon (a long result may take several writes).
// A daemon that is gone is not an error here: PR_SET_PDEATHSIG ends us.
void Send(const std::string& line) { (void)WriteAll(kWorkerMessageFd, line); }

StatusOr<JobOutcome> RunRequest(const WorkerRequest& request) {
  PX_ASSIGN_OR_RETURN(DaemonConfig config, DaemonConfigFromJson(request.config));
  PX_RETURN_IF_ERROR(SetLogLevels(config.log_levels));
  PX_ASSIGN_OR_RETURN(ClipJobOptions options, ClipJobOptionsFromConfig(config));
  JobContext context;
  context.job_id = request.job_id;
  context.capture_dir = request.capture_dir;
  context.clip_path = request.clip_path;
  context.settings = request.settings;
  context.shot = request.shot;
  context.progress = [](const std::string& stage, double fraction) {
    Send(WorkerProgressLine(stage, fraction));
    if (fraction > 0) PauseHereIfAsked(stage);
    return !stop_requested.load();
  };
  return MakeClipJobRunner(options)(context);
}

}  // namespace

int RunJobWorker(pid_t parent) {
  // Die with the daemon: a worker must never outlive it and write a clip nobody journals.
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (::getppid() != parent) return 2;               // the daemon died before the line above took effect
  std::ofstream("/proc/self/oom_score_adj") << 500;  // best effort: under pressure, the job goes first
  struct sigaction term {};
  term.sa_handler = OnTerm;
  ::sigaction(SIGTERM, &term, nullptr);

  std::string text((std::istreambuf_iterator<char>(std::cin)), std::istreambuf_iterator<char>());
  nlohmann::json j = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  StatusOr<WorkerRequest> request = j.is_discarded()
                                        ? StatusOr<WorkerRequest>(InvalidArgumentError("worker request: not JSON"))
                                        : WorkerRequestFromJson(j);
  if (!request.ok()) {
    std::cerr << "parallaxd --job-worker: " << request.status().ToString() << "\n";
    return 2;
  }
  SetLogProcessName("worker " + request->job_id);
  StatusOr<JobOutcome> outcome = InternalError("the job did not run");
  try {
    outcome = RunRequest(*request);
  } catch (const std::exception& e) {  // a runner must not throw; report it rather than abort
    outcome = InternalError(std::string("the job threw: ") + e.what());
  }
  Send(WorkerResultLine(outcome));
  return 0;
}

}  // namespace px::device
