// What passes between the daemon and a job's worker process. The daemon writes one request (a
// JSON object, then end of file) on the worker's stdin; the worker writes JSON lines on its
// message fd (3): any number of progress lines, then exactly one result line.
//   {"progress": {"stage": "depth", "fraction": 0.4}}
//   {"result": {"ok": true, "note": "90 frames ...", "clip_path": "/store/clips/000007.mp4"}}
//   {"result": {"ok": false, "code": "DATA_LOSS", "message": "frame 3: ..."}}
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>

#include "device/daemon.h"
#include "pipeline/core/status.h"

namespace px::device {

inline constexpr int kWorkerMessageFd = 3;
inline constexpr const char* kJobWorkerFlag = "--job-worker";

struct WorkerRequest {
  std::string job_id;
  std::filesystem::path capture_dir;
  std::filesystem::path clip_path;
  PressSettings settings;  // JobContext::settings
  std::string shot;        // JobContext::shot (JSON text)
  nlohmann::json config;   // the daemon's effective config (DaemonConfigToJson)
};

nlohmann::json WorkerRequestToJson(const WorkerRequest& request);
StatusOr<WorkerRequest> WorkerRequestFromJson(const nlohmann::json& j);

std::string WorkerProgressLine(const std::string& stage, double fraction);
std::string WorkerResultLine(const StatusOr<JobOutcome>& outcome);

// One line the worker wrote: a progress report, or its result.
struct WorkerLine {
  std::string stage;  // progress
  double fraction = 0;
  std::optional<StatusOr<JobOutcome>> result;  // set for the result line
};
// DATA_LOSS naming what is wrong for a line that is neither.
StatusOr<WorkerLine> ParseWorkerLine(std::string_view line);

}  // namespace px::device
