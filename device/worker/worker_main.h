// The worker side of worker_runner.h: `parallaxd --job-worker --parent PID` reads one request on
// stdin, makes the clip with the request's config (MakeClipJobRunner), reports progress and the
// result on fd 3 (worker_protocol.h) and exits 0. It dies with the daemon (PR_SET_PDEATHSIG), is
// the OOM killer's first choice (oom_score_adj 500), and stops at the next progress report
// after SIGTERM, returning CANCELLED.
#pragma once

#include <sys/types.h>

namespace px::device {

// The process's exit code: 0 when a result was written (the job's own success or failure), 2
// when the request could not be read or the parent is already gone.
int RunJobWorker(pid_t parent);

}  // namespace px::device
