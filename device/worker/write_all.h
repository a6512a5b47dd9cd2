// Writing a whole buffer to a file descriptor: the daemon's pipes to and from its worker
// processes, and its private files.
#pragma once

#include <string_view>

namespace px::device {

// Writes all of `bytes` to `fd`: short writes continued, EINTR retried. A pipe whose reader is
// gone gives EPIPE, never SIGPIPE (the signal is blocked on this thread meanwhile and a pending
// one consumed), so a dead worker or daemon is an error for the caller, not the end of the
// process. Returns 0, or the errno of the write that failed (EIO for a write of 0 bytes).
int WriteAll(int fd, std::string_view bytes);

}  // namespace px::device
