// The control protocol: JSON lines over a Unix domain socket. One request per line, one reply
// line per request, in order. See README "Control protocol".
//   {"cmd":"capture"}               -> {"ok":true,"job":"000007"}
//   {"cmd":"status"}                -> {"ok":true,"state":"processing","queue":{...},"last_job":{...}}
//   {"cmd":"list"}                  -> {"ok":true,"jobs":[{...}, ...]}
//   {"cmd":"wait","job":"000007"}   -> the reply comes when the job is done or failed: {"ok":true,"job":{...}}
//   {"cmd":"quit"}                  -> {"ok":true}; stops after the current step ("drain":true: after the queue)
// Any problem with a request is {"ok":false,"error":"...","code":"..."} and the connection stays open.
#pragma once

#include <string>
#include <string_view>

#include "pipeline/core/status.h"

namespace px::device {

enum class ControlCommand { kCapture, kStatus, kList, kWait, kQuit };

std::string_view ControlCommandName(ControlCommand command);

struct ControlRequest {
  ControlCommand command = ControlCommand::kStatus;
  std::string job;     // kWait: the job to wait for
  bool drain = false;  // kQuit: finish every queued job first
};

// The longest request line accepted; longer lines are answered with an error and dropped.
inline constexpr size_t kMaxControlLineBytes = 64 * 1024;

// Parses one line (without its newline). Errors say what is wrong:
//   "malformed JSON at byte 7: ...", "cmd: missing", "cmd: 'fly' is not one of capture, status, list, wait, quit",
//   "job: missing (wait needs a job id)", "capture: unknown field 'jbo'".
StatusOr<ControlRequest> ParseControlRequest(std::string_view line);

// {"ok":false,"error":"<message>","code":"INVALID_ARGUMENT"} as one line without the newline.
std::string ControlErrorReply(const Status& status);

}  // namespace px::device
