#include "device/control/control_protocol.h"

#include <algorithm>
#include <nlohmann/json.hpp>

#include "device/storage/job_journal.h"
#include "pipeline/core/json_fields.h"

namespace px::device {
namespace {

// A client's text inside an error message, cut short so a reply never echoes a huge request.
std::string Quoted(std::string_view text) {
  constexpr size_t kMaxEcho = 40;
  if (text.size() <= kMaxEcho) return "'" + std::string(text) + "'";
  return "'" + std::string(text.substr(0, kMaxEcho)) + "...' (" + std::to_string(text.size()) + " bytes)";
}

}  // namespace

std::string_view ControlCommandName(ControlCommand command) {
  switch (command) {
    case ControlCommand::kCapture:
      return "capture";
    case ControlCommand::kStatus:
      return "status";
    case ControlCommand::kList:
      return "list";
    case ControlCommand::kWait:
      return "wait";
    case ControlCommand::kQuit:
      return "quit";
    case ControlCommand::kFetch:
      return "fetch";
    case ControlCommand::kSetMove:
      return "set_move";
    case ControlCommand::kCancel:
      return "cancel";
    case ControlCommand::kSetShot:
      return "set_shot";
    case ControlCommand::kSetSettings:
      return "set_settings";
  }
  return "unknown";
}

StatusOr<ControlRequest> ParseControlRequest(std::string_view line) {
  if (line.size() > kMaxControlLineBytes) {
    return InvalidArgumentError("request of " + std::to_string(line.size()) + " bytes is longer than " +
                                std::to_string(kMaxControlLineBytes));
  }
  PX_ASSIGN_OR_RETURN(nlohmann::json j, json::Parse(std::string(line), "request"));
  if (!j.is_object()) return InvalidArgumentError(std::string("request: want an object, got ") + j.type_name());
  PX_ASSIGN_OR_RETURN(std::string name, json::GetString(j, "cmd", ""));
  ControlRequest request;
  bool found = false;
  for (ControlCommand command : {ControlCommand::kCapture,
                                 ControlCommand::kStatus,
                                 ControlCommand::kList,
                                 ControlCommand::kWait,
                                 ControlCommand::kQuit,
                                 ControlCommand::kFetch,
                                 ControlCommand::kSetMove,
                                 ControlCommand::kCancel,
                                 ControlCommand::kSetShot,
                                 ControlCommand::kSetSettings}) {
    if (ControlCommandName(command) == name) {
      request.command = command;
      found = true;
    }
  }
  if (!found) {
    return InvalidArgumentError(
        "cmd: " + Quoted(name) +
        " is not one of capture, status, list, wait, quit, fetch, set_move, cancel, set_shot, set_settings");
  }

  std::vector<std::string> allowed = {"cmd"};
  if (request.command == ControlCommand::kWait || request.command == ControlCommand::kFetch ||
      request.command == ControlCommand::kCancel) {
    if (!j.contains("job")) return InvalidArgumentError("job: missing (" + name + " needs a job id)");
    PX_ASSIGN_OR_RETURN(request.job, json::GetString(j, "job", ""));
    // Ids name files (captures/<id>, clips/<id>.mp4): only digits get near a path.
    if (!ParseJobId(request.job)) {
      return InvalidArgumentError("job: " + Quoted(request.job) + " is not a job id (1 to 18 digits, e.g. \"000042\")");
    }
    allowed.push_back("job");
  }
  if (request.command == ControlCommand::kFetch) {
    PX_ASSIGN_OR_RETURN(request.inline_bytes, json::GetBoolOr(j, "inline", "", false));
    allowed.push_back("inline");
  }
  if (request.command == ControlCommand::kSetMove) {
    if (!j.contains("move")) return InvalidArgumentError("move: missing (set_move needs a camera move)");
    PX_ASSIGN_OR_RETURN(request.move, json::GetString(j, "move", ""));
    allowed.push_back("move");
  }
  if (request.command == ControlCommand::kSetShot) {
    if (!j.contains("shot")) return InvalidArgumentError("shot: missing (set_shot needs a shot object, or null)");
    const nlohmann::json& shot = j["shot"];
    if (!shot.is_null() && !shot.is_object()) {
      return InvalidArgumentError(std::string("shot: want an object or null, got ") + shot.type_name());
    }
    request.shot = shot.is_null() ? "" : shot.dump();
    allowed.push_back("shot");
  }
  if (request.command == ControlCommand::kSetSettings) {
    nlohmann::json changes = nlohmann::json::object();
    for (const char* field : {"move", "effect", "format", "size"}) {
      if (!j.contains(field)) continue;
      if (!j[field].is_string() && !j[field].is_null()) {
        return InvalidArgumentError(std::string(field) + ": want a string or null, got " + j[field].type_name());
      }
      changes[field] = j[field];
      allowed.push_back(field);
    }
    request.settings = changes.dump();
  }
  if (request.command == ControlCommand::kQuit) {
    PX_ASSIGN_OR_RETURN(request.drain, json::GetBoolOr(j, "drain", "", false));
    allowed.push_back("drain");
  }
  for (const auto& [key, value] : j.items()) {
    if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
      return InvalidArgumentError(name + ": unknown field " + Quoted(key));
    }
  }
  return request;
}

std::string ControlErrorReply(const Status& status) {
  std::string message = status.message();
  if (message.size() > kMaxControlErrorBytes) {
    const size_t full = message.size();
    message.resize(kMaxControlErrorBytes);
    message += "... (" + std::to_string(full) + " bytes)";
  }
  nlohmann::json reply = {{"ok", false}, {"error", message}, {"code", std::string(StatusCodeName(status.code()))}};
  // Replace invalid UTF-8 (a garbled request echoed in the message) instead of throwing.
  return reply.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace px::device
