// The preview worker: the child process behind one authoring session (preview_session.h). It
// builds the capture's scene once (lattice, calibration, depth: pipeline/run BuildPipelineScene),
// then draws frames from any viewpoint the page asks for with the clip's own renderer, as JPEG,
// until its stdin closes. A crash here costs the session, never the daemon.
#pragma once

#include <sys/types.h>

namespace px::device {

// Serves preview_protocol.h on stdin and fd 3; returns the process's exit code.
int RunPreviewWorker(pid_t parent);

}  // namespace px::device
