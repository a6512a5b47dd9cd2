// The JSON API under /api (openapi.yaml): the control socket's commands over HTTP, plus what the
// pages need: a job's details with its clip's report, the clip (with Range, so a video element
// seeks), its poster and preview, delete, and server-sent events for progress and new clips.
#pragma once

#include <atomic>
#include <filesystem>
#include <memory>
#include <string>

#include "device/http/event_hub.h"
#include "device/preview/preview_session.h"

namespace httplib {
class Server;
}

namespace px::device {

class Daemon;

struct ApiContext {
  Daemon* daemon = nullptr;
  std::shared_ptr<EventHub> events;
  std::shared_ptr<std::atomic<int>> event_streams;  // open /api/events streams
  int max_event_streams = 8;
  std::string token;                          // for the QR code shown at the device
  std::string listen_host;                    // the address the server listens on
  std::shared_ptr<PreviewSessions> previews;  // authoring's live previews
};

void RegisterApiRoutes(httplib::Server& server, const ApiContext& api);

// The Content-Type of a file the server sends (a clip, a poster, a page), by its extension.
std::string ContentTypeFor(const std::filesystem::path& path);

// The HTTP status for a control reply's "code" (StatusCodeName): NOT_FOUND 404, ...
int HttpStatusForCode(const std::string& code);

}  // namespace px::device
