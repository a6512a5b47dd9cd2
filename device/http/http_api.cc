#include "device/http/http_api.h"

#include <httplib.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <vector>

#include "device/daemon.h"
#include "device/http/access_token.h"
#include "device/storage/storage_layout.h"
#include "pipeline/core/log.h"

namespace px::device {

namespace {

namespace fs = std::filesystem;
using httplib::Request;
using httplib::Response;

// Job ids are digits (JobJournal::NewId); the routes match nothing else, so no path parameter can
// name a file outside the store ("..", "%2e%2e", "/etc/passwd" all fail to match: 404).
constexpr char kJob[] = R"(/api/jobs/([0-9]{1,18}))";
constexpr size_t kFileChunkBytes = 64 * 1024;
constexpr auto kEventWait = std::chrono::seconds(15);  // a keep-alive comment at least this often

void Reply(Response& res, int status, const nlohmann::json& body) {
  res.status = status;
  res.set_header("Cache-Control", "no-store");
  res.set_content(body.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace), "application/json");
}

void ReplyError(Response& res, int status, const std::string& message) {
  Reply(res, status, {{"ok", false}, {"error", message}});
}

void ReplyStatus(Response& res, const Status& status) {
  ReplyError(res, HttpStatusForCode(std::string(StatusCodeName(status.code()))), status.message());
}

// A control request answered through the daemon, exactly as the control socket answers it.
void AnswerControl(const ApiContext& api, const nlohmann::json& request, Response& res, int ok_status = 200) {
  std::string reply;
  api.daemon->HandleControlRequest(request.dump(), [&reply](const std::string& line) { reply = line; });
  nlohmann::json body = nlohmann::json::parse(reply, nullptr, /*allow_exceptions=*/false);
  if (body.is_discarded()) return ReplyError(res, 500, "the daemon's reply was not JSON");
  if (body.value("ok", false)) return Reply(res, ok_status, body);
  Reply(res, HttpStatusForCode(body.value("code", "")), body);
}

// Parses a JSON request body; replies 400 naming the problem when it is not a JSON object.
std::optional<nlohmann::json> JsonBody(const Request& req, Response& res) {
  nlohmann::json body = nlohmann::json::parse(req.body, nullptr, /*allow_exceptions=*/false);
  if (body.is_discarded() || !body.is_object()) {
    ReplyError(res, 400, "the request body must be a JSON object");
    return std::nullopt;
  }
  return body;
}

// Streams a file; the library answers Range requests (206) from a provider of known length.
void ServeFile(const fs::path& path, Response& res, const std::string& download_name = "") {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return ReplyError(res, 404, "no such file for this job");
  const uint64_t size = fs::file_size(path, ec);
  auto file = std::make_shared<std::ifstream>(path, std::ios::binary);
  if (ec || !*file) return ReplyError(res, 500, "cannot read " + path.filename().string());
  if (!download_name.empty()) res.set_header("Content-Disposition", "inline; filename=\"" + download_name + "\"");
  res.set_header("Cache-Control", "private, max-age=3600");
  res.set_content_provider(size, ContentTypeFor(path), [file](size_t offset, size_t length, httplib::DataSink& sink) {
    std::vector<char> buffer(std::min(length, kFileChunkBytes));
    file->clear();
    file->seekg(static_cast<std::streamoff>(offset));
    file->read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    const std::streamsize got = file->gcount();
    return got > 0 && sink.write(buffer.data(), static_cast<size_t>(got));
  });
}

std::optional<JobRecord> FindJob(const ApiContext& api, const Request& req, Response& res) {
  std::optional<JobRecord> record = api.daemon->Job(req.matches[1]);
  if (!record) ReplyError(res, 404, "job '" + std::string(req.matches[1]) + "': no such job");
  return record;
}

nlohmann::json JobLinks(const std::string& id) {
  const std::string base = "/api/jobs/" + id;
  return {
      {"clip", base + "/clip"}, {"poster", base + "/poster"}, {"preview", base + "/preview"}, {"shot", base + "/shot"}};
}

void JobDetails(const ApiContext& api, const Request& req, Response& res) {
  std::optional<JobRecord> record = FindJob(api, req, res);
  if (!record) return;
  const fs::path clip = api.daemon->layout().FindClip(record->id);
  nlohmann::json report = nullptr;
  if (auto text = std::ifstream(ClipReportPathFor(clip))) {
    report = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
    if (report.is_discarded()) report = nullptr;
  }
  std::error_code ec;
  Reply(res,
        200,
        {{"ok", true},
         {"job", JobRecordToJson(*record)},
         {"report", report},
         {"links", JobLinks(record->id)},
         {"files",
          {{"clip", fs::exists(clip, ec) ? nlohmann::json(clip.filename().string()) : nlohmann::json(nullptr)},
           {"poster", fs::exists(ClipPosterPathFor(clip), ec)},
           {"preview", fs::exists(ClipPreviewPathFor(clip), ec)},
           {"shot", fs::exists(ClipShotPathFor(clip), ec)}}}});
}

void ServeJobFile(const ApiContext& api, const Request& req, Response& res, const std::string& which) {
  std::optional<JobRecord> record = FindJob(api, req, res);
  if (!record) return;
  const fs::path clip = api.daemon->layout().FindClip(record->id);
  std::error_code ec;
  if (which == "clip") {
    if (fs::is_directory(clip, ec)) {
      return ReplyError(res, 409, "job " + record->id + "'s clip is a folder of PNG frames (clip.format png)");
    }
    return ServeFile(clip, res, "parallax-" + record->id + clip.extension().string());
  }
  if (which == "shot") return ServeFile(ClipShotPathFor(clip), res);
  ServeFile(which == "poster" ? ClipPosterPathFor(clip) : ClipPreviewPathFor(clip), res);
}

// An authored shot rendered on a job's capture: a new job, in the gallery once its clip is made.
void RenderShot(const ApiContext& api, const Request& req, Response& res) {
  std::optional<nlohmann::json> body = JsonBody(req, res);
  if (!body) return;
  if (!body->contains("shot") || !(*body)["shot"].is_object()) {
    return ReplyError(res, 400, "shot: missing or not an object (a shot file, pipeline/direct/SHOT_FORMAT.md)");
  }
  StatusOr<std::string> job = api.daemon->RenderShot(req.matches[1], (*body)["shot"].dump());
  if (!job.ok()) {
    return ReplyStatus(res, job.status());
  }
  Reply(res, 202, {{"ok", true}, {"job", *job}});
}

// The job's live preview session, opened (its scene built) on first use.
StatusOr<std::shared_ptr<PreviewSession>> PreviewFor(const ApiContext& api, const std::string& id) {
  if (!api.previews || !api.previews->enabled()) return UnavailableError("live previews are off in this server");
  std::optional<JobRecord> record = api.daemon->Job(id);
  if (!record) return NotFoundError("job '" + id + "': no such job");
  if (record->capture_dir.empty()) return FailedPreconditionError("job " + id + " has no saved capture");
  return api.previews->ForJob(id, record->capture_dir);
}

void OpenPreview(const ApiContext& api, const Request& req, Response& res) {
  StatusOr<std::shared_ptr<PreviewSession>> session = PreviewFor(api, req.matches[1]);
  if (!session.ok()) return ReplyStatus(res, session.status());
  Reply(res, 200, {{"ok", true}, {"scene", (*session)->scene()}});
}

void ServePreviewFrame(const ApiContext& api, const Request& req, Response& res) {
  std::optional<nlohmann::json> viewpoint = JsonBody(req, res);
  if (!viewpoint) return;
  StatusOr<std::shared_ptr<PreviewSession>> session = PreviewFor(api, req.matches[1]);
  if (!session.ok()) return ReplyStatus(res, session.status());
  for (const char* flag : {"coverage", "draft", "lossless"}) {
    if (viewpoint->contains(flag) && !(*viewpoint)[flag].is_boolean()) {
      return ReplyError(res, 400, std::string(flag) + ": want true or false");
    }
  }
  const bool coverage = viewpoint->value("coverage", false);
  const bool draft = viewpoint->value("draft", false);
  const bool lossless = viewpoint->value("lossless", false);
  viewpoint->erase("coverage");
  viewpoint->erase("draft");
  viewpoint->erase("lossless");
  StatusOr<PreviewFrame> frame = (*session)->Frame(*viewpoint, coverage, draft, lossless);
  if (!frame.ok()) return ReplyStatus(res, frame.status());
  res.set_header("Cache-Control", "no-store");
  res.set_header("X-Preview", frame->figures.dump());
  res.set_content(frame->image, frame->mime);
}

// The preview's scene for a renderer in the browser (pipeline/render/gl/web_scene.h).
void ServePreviewScene(const ApiContext& api, const Request& req, Response& res) {
  StatusOr<std::shared_ptr<PreviewSession>> session = PreviewFor(api, req.matches[1]);
  if (!session.ok()) return ReplyStatus(res, session.status());
  StatusOr<std::string> scene = (*session)->SceneExport();
  if (!scene.ok()) return ReplyStatus(res, scene.status());
  res.set_header("Cache-Control", "no-store");
  res.set_content(std::move(*scene), "application/octet-stream");
}

void PreviewProbe(const ApiContext& api, const Request& req, Response& res) {
  std::optional<nlohmann::json> body = JsonBody(req, res);
  if (!body) return;
  if (!body->contains("viewpoint") || !(*body)["x"].is_number() || !(*body)["y"].is_number()) {
    return ReplyError(res, 400, "want {viewpoint, x, y}");
  }
  StatusOr<std::shared_ptr<PreviewSession>> session = PreviewFor(api, req.matches[1]);
  if (!session.ok()) return ReplyStatus(res, session.status());
  StatusOr<nlohmann::json> point =
      (*session)->Probe((*body)["viewpoint"], (*body)["x"].get<int>(), (*body)["y"].get<int>());
  if (!point.ok()) return ReplyStatus(res, point.status());
  (*point)["ok"] = true;
  Reply(res, 200, *point);
}

void PreviewRegion(const ApiContext& api, const Request& req, Response& res) {
  std::optional<nlohmann::json> body = JsonBody(req, res);
  if (!body) return;
  if (!body->contains("viewpoint") || !body->contains("rect")) return ReplyError(res, 400, "want {viewpoint, rect}");
  StatusOr<std::shared_ptr<PreviewSession>> session = PreviewFor(api, req.matches[1]);
  if (!session.ok()) return ReplyStatus(res, session.status());
  StatusOr<nlohmann::json> region = (*session)->Region((*body)["viewpoint"], (*body)["rect"]);
  if (!region.ok()) return ReplyStatus(res, region.status());
  (*region)["ok"] = true;
  Reply(res, 200, *region);
}

void PreviewMap(const ApiContext& api, const Request& req, Response& res) {
  std::optional<nlohmann::json> body = JsonBody(req, res);
  if (!body) return;
  if (!body->contains("viewpoint")) return ReplyError(res, 400, "want {viewpoint, cells}");
  const nlohmann::json& cells = body->value("cells", nlohmann::json(12));
  if (!cells.is_number_integer() || cells.get<int64_t>() < 3 || cells.get<int64_t>() > 32)
    return ReplyError(res, 400, "cells: want an integer in [3, 32]");
  StatusOr<std::shared_ptr<PreviewSession>> session = PreviewFor(api, req.matches[1]);
  if (!session.ok()) return ReplyStatus(res, session.status());
  StatusOr<nlohmann::json> map = (*session)->Map((*body)["viewpoint"], cells.get<int>());
  if (!map.ok()) return ReplyStatus(res, map.status());
  (*map)["ok"] = true;
  Reply(res, 200, *map);
}

void DeleteJob(const ApiContext& api, const Request& req, Response& res) {
  const std::string id = req.matches[1];
  if (api.previews) api.previews->Close(id);
  Status deleted = api.daemon->DeleteJob(id);
  if (!deleted.ok())
    return ReplyError(res, HttpStatusForCode(std::string(StatusCodeName(deleted.code()))), deleted.message());
  Reply(res, 200, {{"ok", true}, {"deleted", id}});
}

// Server-sent events: every daemon event as `data:` JSON with its number as `id:`, so a browser's
// EventSource resumes after a reconnect; "resync" when some were missed.
void EventStream(const ApiContext& api, const Request& req, Response& res) {
  if (api.event_streams->fetch_add(1) >= api.max_event_streams) {
    api.event_streams->fetch_sub(1);
    res.set_header("Retry-After", "5");
    return ReplyError(res, 503, "too many event streams open (" + std::to_string(api.max_event_streams) + ")");
  }
  auto after = std::make_shared<uint64_t>(api.events->LastId());
  const std::string last_seen = req.get_header_value("Last-Event-ID");
  if (!last_seen.empty() && last_seen.size() < 20 && last_seen.find_first_not_of("0123456789") == std::string::npos) {
    *after = std::stoull(last_seen);
  }
  auto first = std::make_shared<bool>(true);
  res.set_header("Cache-Control", "no-store");
  res.set_chunked_content_provider(
      "text/event-stream",
      [events = api.events, after, first](size_t, httplib::DataSink& sink) {
        std::string out;
        if (*first) {
          *first = false;
          out = "retry: 2000\n: parallax events\n\n";  // sent at once, so the browser sees the stream open
        } else {
          bool missed = false;
          const std::vector<NumberedEvent> batch = events->WaitAfter(*after, kEventWait, &missed);
          if (events->closed()) {
            sink.done();
            return true;
          }
          if (missed) out += "event: resync\ndata: {}\n\n";
          for (const NumberedEvent& event : batch) {
            out += "id: " + std::to_string(event.id) + "\ndata: " + event.data + "\n\n";
            *after = event.id;
          }
          if (out.empty()) out = ": keep-alive\n\n";
        }
        return sink.write(out.data(), out.size());
      },
      [streams = api.event_streams](bool) { streams->fetch_sub(1); });
}

void Login(const Request& req, Response& res, const std::string& token) {
  std::string presented;
  if (req.has_param("token")) {
    presented = req.get_param_value("token");
  } else {
    nlohmann::json body = nlohmann::json::parse(req.body, nullptr, /*allow_exceptions=*/false);
    if (body.is_object() && body.contains("token") && body["token"].is_string()) presented = body["token"];
  }
  if (presented.empty() || !TokensEqual(presented, token)) {
    Logger("http")->info("login from {} refused: wrong token", req.remote_addr);
    return ReplyError(res, 401, "wrong access token");
  }
  res.set_header("Set-Cookie", LoginCookie(token));
  Reply(res, 200, {{"ok", true}});
}

}  // namespace

std::string ContentTypeFor(const std::filesystem::path& path) {
  const std::string ext = path.extension().string();
  if (ext == ".mp4") return "video/mp4";
  if (ext == ".gif") return "image/gif";
  if (ext == ".webp") return "image/webp";
  if (ext == ".jpg") return "image/jpeg";
  if (ext == ".json") return "application/json";
  if (ext == ".html") return "text/html; charset=utf-8";
  if (ext == ".js") return "text/javascript; charset=utf-8";
  if (ext == ".css") return "text/css; charset=utf-8";
  if (ext == ".svg") return "image/svg+xml";
  if (ext == ".yaml") return "application/yaml";
  return "application/octet-stream";
}

int HttpStatusForCode(const std::string& code) {
  if (code == "INVALID_ARGUMENT" || code == "OUT_OF_RANGE") return 400;
  if (code == "NOT_FOUND") return 404;
  if (code == "FAILED_PRECONDITION" || code == "ALREADY_EXISTS") return 409;
  if (code == "RESOURCE_EXHAUSTED") return 507;
  if (code == "UNAVAILABLE") return 503;
  if (code == "DEADLINE_EXCEEDED") return 504;
  if (code == "UNIMPLEMENTED") return 501;
  return 500;
}

void RegisterApiRoutes(httplib::Server& server, const ApiContext& api) {
  server.Get("/api/status", [api](const Request&, Response& res) { AnswerControl(api, {{"cmd", "status"}}, res); });
  server.Get("/api/jobs", [api](const Request&, Response& res) { AnswerControl(api, {{"cmd", "list"}}, res); });
  server.Post("/api/press", [api](const Request&, Response& res) {
    AnswerControl(api, {{"cmd", "capture"}}, res, 202);
  });
  server.Get(kJob, [api](const Request& req, Response& res) { JobDetails(api, req, res); });
  server.Delete(kJob, [api](const Request& req, Response& res) { DeleteJob(api, req, res); });
  server.Post(std::string(kJob) + "/cancel", [api](const Request& req, Response& res) {
    AnswerControl(api, {{"cmd", "cancel"}, {"job", std::string(req.matches[1])}}, res);
  });
  server.Post(std::string(kJob) + "/render", [api](const Request& req, Response& res) { RenderShot(api, req, res); });
  server.Post(std::string(kJob) + "/preview", [api](const Request& req, Response& res) { OpenPreview(api, req, res); });
  server.Post(std::string(kJob) + "/preview/frame",
              [api](const Request& req, Response& res) { ServePreviewFrame(api, req, res); });
  // A POST, as opening a preview is: it may build a scene (seconds), so another site must not ask.
  server.Post(std::string(kJob) + "/preview/scene",
              [api](const Request& req, Response& res) { ServePreviewScene(api, req, res); });
  server.Post(std::string(kJob) + "/preview/probe",
              [api](const Request& req, Response& res) { PreviewProbe(api, req, res); });
  server.Post(std::string(kJob) + "/preview/region",
              [api](const Request& req, Response& res) { PreviewRegion(api, req, res); });
  server.Post(std::string(kJob) + "/preview/map",
              [api](const Request& req, Response& res) { PreviewMap(api, req, res); });
  server.Delete(std::string(kJob) + "/preview", [api](const Request& req, Response& res) {
    if (api.previews) api.previews->Close(req.matches[1]);
    Reply(res, 200, {{"ok", true}});
  });
  for (const std::string which : {"clip", "poster", "preview", "shot"}) {
    server.Get(std::string(kJob) + "/" + which,
               [api, which](const Request& req, Response& res) { ServeJobFile(api, req, res, which); });
  }
  server.Put("/api/settings/move", [api](const Request& req, Response& res) {
    std::optional<nlohmann::json> body = JsonBody(req, res);
    if (!body) return;
    if (!body->contains("move") || !(*body)["move"].is_string())
      return ReplyError(res, 400, "move: missing or not a string");
    AnswerControl(api, {{"cmd", "set_move"}, {"move", (*body)["move"]}}, res);
  });
  server.Put("/api/settings", [api](const Request& req, Response& res) {
    std::optional<nlohmann::json> body = JsonBody(req, res);
    if (!body) return;
    nlohmann::json request = *body;
    request["cmd"] = "set_settings";
    AnswerControl(api, request, res);
  });
  server.Put("/api/settings/shot", [api](const Request& req, Response& res) {
    std::optional<nlohmann::json> body = JsonBody(req, res);
    if (!body) return;
    if (!body->contains("shot")) return ReplyError(res, 400, "shot: missing (a shot object, or null for none)");
    AnswerControl(api, {{"cmd", "set_shot"}, {"shot", (*body)["shot"]}}, res);
  });
  server.Get("/api/events", [api](const Request& req, Response& res) { EventStream(api, req, res); });
  server.Post("/api/login", [api](const Request& req, Response& res) { Login(req, res, api.token); });
  server.Post("/api/logout", [](const Request&, Response& res) {
    res.set_header("Set-Cookie", "px_token=; Path=/; HttpOnly; SameSite=Strict; Max-Age=0");
    Reply(res, 200, {{"ok", true}});
  });
}

}  // namespace px::device
