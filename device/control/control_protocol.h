// The control protocol: JSON lines over a Unix domain socket. One request per line, one reply
// line per request, in order. See README "Control protocol".
//   {"cmd":"capture"}               -> {"ok":true,"job":"000007"}
//   {"cmd":"status"}                -> {"ok":true,"state":"processing","queue":{...},"last_job":{...}}
//   {"cmd":"list"}                  -> {"ok":true,"jobs":[{...}, ...]}
//   {"cmd":"wait","job":"000007"}   -> the reply comes when the job is done or failed: {"ok":true,"job":{...}}
//   {"cmd":"quit"}                  -> {"ok":true}; stops after the current step ("drain":true: after the queue)
//   {"cmd":"fetch","job":"000007"}  -> {"ok":true,"job":"000007","path":"/.../000007.mp4","bytes":N,"sha256":"..."}
//                                      ("inline":true adds "data": the clip's bytes in base64, up to a size limit)
//   {"cmd":"set_move","move":"establishing_dolly"} -> {"ok":true,"move":"..."}; jobs pressed from now on use it
//   {"cmd":"set_shot","shot":{...}} -> {"ok":true,"shot":{...},"segments":N}; jobs pressed from now on follow the
//                                      shot (pipeline/direct/SHOT_FORMAT.md); "shot":null goes back to the move
//   {"cmd":"set_settings","format":"gif","size":null} -> {"ok":true,"settings":{"move":..,"effect":..,"format":..,
//                                      "size":..}}; the fields given change (null: back to the config's), the
//                                      rest stay; jobs pressed from now on use them; kept across restarts
//   {"cmd":"cancel","job":"000007"} -> {"ok":true,"job":"000007","was":"saved"}; a queued job or the running
//                                      clip stops and fails as CANCELLED; its raw capture is kept
// Any problem with a request is {"ok":false,"error":"...","code":"..."} and the connection stays open.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "pipeline/core/status.h"

namespace px::device {

enum class ControlCommand { kCapture, kStatus, kList, kWait, kQuit, kFetch, kSetMove, kCancel, kSetShot, kSetSettings };

std::string_view ControlCommandName(ControlCommand command);

struct ControlRequest {
  ControlCommand command = ControlCommand::kStatus;
  std::string job;            // kWait, kFetch, kCancel: the job
  bool drain = false;         // kQuit: finish every queued job first
  bool inline_bytes = false;  // kFetch: the clip's bytes in the reply, base64 ("inline")
  std::string move;           // kSetMove: the camera move (validated by the daemon against pipeline/direct)
  std::string shot;           // kSetShot: the shot as JSON text (validated by the daemon); "" = none (null)
  std::string settings;       // kSetSettings: the fields to change, a JSON object's text (validated by the daemon)
};

// The longest request line accepted; longer lines are answered with an error and dropped.
inline constexpr size_t kMaxControlLineBytes = 64 * 1024;
// Connections open at once; more are answered with RESOURCE_EXHAUSTED and closed.
inline constexpr size_t kMaxControlConnections = 32;
// Error messages in replies are cut to this many bytes (a malformed request is never echoed whole).
inline constexpr size_t kMaxControlErrorBytes = 1024;
// The largest clip a "fetch" with "inline":true sends in the reply (base64 makes it 4/3 larger);
// larger clips are refused with OUT_OF_RANGE and should be read from their path.
inline constexpr uint64_t kMaxInlineClipBytes = 16 * 1000 * 1000;

// Parses one line (without its newline). Errors say what is wrong:
//   "malformed JSON at byte 7: ...", "cmd: missing",
//   "cmd: 'fly' is not one of capture, status, list, wait, quit, fetch, set_move, cancel, set_shot, set_settings",
//   "job: missing (wait needs a job id)", "capture: unknown field 'jbo'",
//   "job: '../x' is not a job id (1 to 18 digits, e.g. "000042")". Client text quoted in an
//   error is cut to 40 bytes.
StatusOr<ControlRequest> ParseControlRequest(std::string_view line);

// {"ok":false,"error":"<message>","code":"INVALID_ARGUMENT"} as one line without the newline;
// the message is cut to kMaxControlErrorBytes and invalid UTF-8 replaced.
std::string ControlErrorReply(const Status& status);

}  // namespace px::device
