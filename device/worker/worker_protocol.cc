#include "device/worker/worker_protocol.h"

#include "pipeline/core/json_fields.h"

namespace px::device {

nlohmann::json WorkerRequestToJson(const WorkerRequest& request) {
  return {{"job_id", request.job_id},
          {"capture_dir", request.capture_dir.string()},
          {"clip_path", request.clip_path.string()},
          {"move", request.settings.move},
          {"effect", request.settings.effect},
          {"format", request.settings.format},
          {"size", request.settings.size},
          {"shot", request.shot},
          {"config", request.config}};
}

StatusOr<WorkerRequest> WorkerRequestFromJson(const nlohmann::json& j) {
  const std::string what = "worker request";
  WorkerRequest request;
  PX_ASSIGN_OR_RETURN(request.job_id, json::GetString(j, "job_id", what));
  PX_ASSIGN_OR_RETURN(std::string capture_dir, json::GetString(j, "capture_dir", what));
  PX_ASSIGN_OR_RETURN(std::string clip_path, json::GetString(j, "clip_path", what));
  request.capture_dir = capture_dir;
  request.clip_path = clip_path;
  PX_ASSIGN_OR_RETURN(request.settings.move, json::GetStringOr(j, "move", what, ""));
  PX_ASSIGN_OR_RETURN(request.settings.effect, json::GetStringOr(j, "effect", what, ""));
  PX_ASSIGN_OR_RETURN(request.settings.format, json::GetStringOr(j, "format", what, ""));
  PX_ASSIGN_OR_RETURN(request.settings.size, json::GetStringOr(j, "size", what, ""));
  PX_ASSIGN_OR_RETURN(request.shot, json::GetStringOr(j, "shot", what, ""));
  PX_ASSIGN_OR_RETURN(const nlohmann::json* config, json::GetField(j, "config", what));
  if (!config->is_object()) return InvalidArgumentError(what + ".config: want an object");
  request.config = *config;
  return request;
}

std::string WorkerProgressLine(const std::string& stage, double fraction) {
  return nlohmann::json({{"progress", {{"stage", stage}, {"fraction", fraction}}}}).dump() + "\n";
}

std::string WorkerResultLine(const StatusOr<JobOutcome>& outcome) {
  nlohmann::json result;
  if (outcome.ok()) {
    result = {{"ok", true}, {"note", outcome->note}, {"clip_path", outcome->clip_path.string()}};
  } else {
    result = {{"ok", false},
              {"code", std::string(StatusCodeName(outcome.status().code()))},
              {"message", outcome.status().message()}};
  }
  // A message may hold bytes that are not UTF-8 (a file name): replace them rather than throw.
  return nlohmann::json({{"result", result}}).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

StatusOr<WorkerLine> ParseWorkerLine(std::string_view line) {
  const std::string what = "worker message";
  nlohmann::json j = nlohmann::json::parse(line, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded() || !j.is_object()) {
    return DataLossError(what + ": not a JSON object: '" + std::string(line.substr(0, 80)) + "'");
  }
  WorkerLine parsed;
  if (auto progress = j.find("progress"); progress != j.end()) {
    PX_ASSIGN_OR_RETURN(parsed.stage, json::GetString(*progress, "stage", what + ".progress"));
    PX_ASSIGN_OR_RETURN(parsed.fraction, json::GetNumber(*progress, "fraction", what + ".progress"));
    return parsed;
  }
  auto result = j.find("result");
  if (result == j.end()) return DataLossError(what + ": neither progress nor result");
  PX_ASSIGN_OR_RETURN(bool ok, json::GetBool(*result, "ok", what + ".result"));
  if (ok) {
    JobOutcome outcome;
    PX_ASSIGN_OR_RETURN(outcome.note, json::GetStringOr(*result, "note", what + ".result", ""));
    PX_ASSIGN_OR_RETURN(std::string clip_path, json::GetStringOr(*result, "clip_path", what + ".result", ""));
    outcome.clip_path = clip_path;
    parsed.result = StatusOr<JobOutcome>(std::move(outcome));
    return parsed;
  }
  PX_ASSIGN_OR_RETURN(std::string code_name, json::GetString(*result, "code", what + ".result"));
  PX_ASSIGN_OR_RETURN(std::string message, json::GetString(*result, "message", what + ".result"));
  const std::optional<StatusCode> code = StatusCodeFromName(code_name);
  if (!code || *code == StatusCode::kOk) return DataLossError(what + ": unknown status code '" + code_name + "'");
  parsed.result = StatusOr<JobOutcome>(Status(*code, message));
  return parsed;
}

}  // namespace px::device
