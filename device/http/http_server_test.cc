// The web app's server inside a real daemon (the simulated camera, the real pipeline in worker
// processes), driven by a real HTTP client: the API, the pages, the event stream, and what a
// hostile or careless client does to it.
#include "device/http/http_server.h"

#include <arpa/inet.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <httplib.h>
#include <ifaddrs.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <regex>
#include <thread>

#include "device/daemon.h"
#include "device/daemon_factory.h"
#include "device/http/web_assets.h"
#include "device/http/web_pages.h"
#include "device/small_daemon_config.h"
#include "tests/testing/temp_dir.h"
#include "tests/testing/video_probe.h"

namespace px::device {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

// The small simulated camera (a job takes seconds), with no control socket: the web API is the way in.
DaemonConfig SmallConfig(const fs::path& dir) {
  DaemonConfig config = SmallDaemonConfig(dir);
  config.control_socket = "";
  return config;
}

// A daemon with its web server on a free loopback port.
struct Camera {
  std::unique_ptr<Daemon> daemon;
  std::unique_ptr<HttpServer> http;

  static std::unique_ptr<Camera> Start(const fs::path& dir, HttpServerOptions options) {
    auto camera = std::make_unique<Camera>();
    auto daemon = BuildDaemon(SmallConfig(dir), BuiltWorkerFlags());
    EXPECT_TRUE(daemon.ok()) << daemon.status().ToString();
    if (!daemon.ok()) return nullptr;
    camera->daemon = std::move(daemon).value();
    options.port = 0;
    options.token_path = dir / "store" / "http_token";
    options.preview.binary = BuiltWorkerFlags().worker_binary;
    options.preview.config = DaemonConfigToJson(SmallConfig(dir));
    camera->http = std::make_unique<HttpServer>(options, camera->daemon.get());
    Status started = camera->daemon->Start();
    EXPECT_TRUE(started.ok()) << started.ToString();
    Status serving = camera->http->Start();
    EXPECT_TRUE(serving.ok()) << serving.ToString();
    return camera;
  }
  ~Camera() {
    if (http) http->Stop();
    if (daemon) {
      daemon->RequestStop(false);
      daemon->Wait();
    }
  }
  httplib::Client Client(const std::string& host = "127.0.0.1") const {
    httplib::Client client(host, http->port());
    client.set_read_timeout(30);
    return client;
  }
};

nlohmann::json Json(const httplib::Result& result) {
  if (!result) return nullptr;
  return nlohmann::json::parse(result->body, nullptr, /*allow_exceptions=*/false);
}

// Collects the event stream's `data:` lines on a thread until `until` accepts one.
class EventReader {
 public:
  EventReader(const Camera& camera, std::function<bool(const nlohmann::json&)> until)
      : client_(camera.Client()), until_(std::move(until)) {
    thread_ = std::thread([this] {
      std::string pending;
      client_.Get("/api/events", [&](const char* data, size_t size) {
        opened_ = true;
        pending.append(data, size);
        for (size_t end; (end = pending.find("\n\n")) != std::string::npos;) {
          const std::string block = pending.substr(0, end);
          pending.erase(0, end + 2);
          const size_t at = block.find("data: ");
          if (at == std::string::npos) continue;
          nlohmann::json event = nlohmann::json::parse(block.substr(at + 6), nullptr, false);
          std::lock_guard<std::mutex> lock(mutex_);
          events_.push_back(event);
          if (until_(event)) {
            done_ = true;
            return false;
          }
        }
        return !stop_.load();
      });
    });
    // Events published before the stream opened are not sent on it: wait for its first bytes.
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (!opened_ && std::chrono::steady_clock::now() < end)
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ~EventReader() {
    stop_ = true;
    client_.stop();
    thread_.join();
  }
  bool WaitDone(std::chrono::seconds limit) {
    const auto end = std::chrono::steady_clock::now() + limit;
    while (std::chrono::steady_clock::now() < end) {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        if (done_) return true;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return false;
  }
  std::vector<nlohmann::json> Events() {
    std::lock_guard<std::mutex> lock(mutex_);
    return events_;
  }

 private:
  httplib::Client client_;
  std::function<bool(const nlohmann::json&)> until_;
  std::thread thread_;
  std::mutex mutex_;
  std::vector<nlohmann::json> events_;
  bool done_ = false;
  std::atomic<bool> stop_{false};
  std::atomic<bool> opened_{false};
};

// Sends raw bytes on a new connection and returns what comes back before the server closes it
// or `wait` passes.
std::string RawExchange(int port, const std::string& bytes, std::chrono::milliseconds wait) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0) {
    close(fd);
    return "<connect failed>";
  }
  if (!bytes.empty()) (void)!write(fd, bytes.data(), bytes.size());
  timeval timeout{static_cast<time_t>(wait.count() / 1000), static_cast<suseconds_t>((wait.count() % 1000) * 1000)};
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof(timeout));
  std::string reply;
  char buffer[4096];
  for (ssize_t got; (got = read(fd, buffer, sizeof(buffer))) > 0;) reply.append(buffer, static_cast<size_t>(got));
  close(fd);
  return reply;
}

// One daemon, pressed once through the API, shared by the tests that read its job.
class HttpApiTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new px::testing::TempDir();
    camera_ = Camera::Start(dir_->path(), HttpServerOptions{}).release();
    ASSERT_NE(camera_, nullptr);
    EventReader reader(*camera_, [](const nlohmann::json& event) {
      return event.value("type", "") == "job" &&
             (event["job"].value("state", "") == "done" || event["job"].value("state", "") == "failed");
    });
    httplib::Client client = camera_->Client();
    auto pressed = client.Post("/api/press");
    ASSERT_TRUE(pressed);
    ASSERT_EQ(pressed->status, 202) << pressed->body;
    job_ = new std::string(Json(pressed)["job"].get<std::string>());
    ASSERT_TRUE(reader.WaitDone(std::chrono::seconds(120))) << "no done event for job " << *job_;
    events_ = new std::vector<nlohmann::json>(reader.Events());
  }
  static void TearDownTestSuite() {
    delete camera_;
    delete dir_;
    delete job_;
    delete events_;
  }
  static px::testing::TempDir* dir_;
  static Camera* camera_;
  static std::string* job_;
  static std::vector<nlohmann::json>* events_;
};
px::testing::TempDir* HttpApiTest::dir_ = nullptr;
Camera* HttpApiTest::camera_ = nullptr;
std::string* HttpApiTest::job_ = nullptr;
std::vector<nlohmann::json>* HttpApiTest::events_ = nullptr;

TEST_F(HttpApiTest, PressStreamsProgressThenTheClip) {
  std::vector<std::string> states;
  std::set<std::string> stages;
  for (const nlohmann::json& event : *events_) {
    if (event["type"] == "job" && event["job"]["id"] == *job_) states.push_back(event["job"]["state"]);
    if (event["type"] == "progress" && event["job"] == *job_) stages.insert(event["stage"].get<std::string>());
  }
  EXPECT_THAT(states, ::testing::ElementsAre("capturing", "saved", "processing", "done"));
  EXPECT_THAT(stages, ::testing::IsSupersetOf({"depth", "render"}));
}

TEST_F(HttpApiTest, JobsListAndDetails) {
  httplib::Client client = camera_->Client();
  nlohmann::json list = Json(client.Get("/api/jobs"));
  ASSERT_TRUE(list["ok"].get<bool>());
  ASSERT_EQ(list["jobs"].size(), 1u);
  EXPECT_EQ(list["jobs"][0]["state"], "done");

  auto details = client.Get("/api/jobs/" + *job_);
  ASSERT_TRUE(details);
  ASSERT_EQ(details->status, 200) << details->body;
  nlohmann::json job = Json(details);
  EXPECT_EQ(job["job"]["id"], *job_);
  EXPECT_EQ(job["files"]["clip"], *job_ + ".mp4");
  EXPECT_TRUE(job["files"]["poster"].get<bool>());
  // The report says which move made the clip and how long each stage took.
  EXPECT_TRUE(job["report"]["camera_path"]["move"].is_string());
  EXPECT_TRUE(job["report"]["timings_ms"].contains("depth"));

  EXPECT_EQ(client.Get("/api/jobs/999999")->status, 404);
  EXPECT_EQ(Json(client.Get("/api/status"))["jobs"]["done"], 1);
}

TEST_F(HttpApiTest, ClipServedWholeAndInRanges) {
  httplib::Client client = camera_->Client();
  const fs::path clip = camera_->daemon->layout().FindClip(*job_);
  std::ifstream file(clip, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 1000u);

  auto whole = client.Get("/api/jobs/" + *job_ + "/clip");
  ASSERT_TRUE(whole);
  EXPECT_EQ(whole->status, 200);
  EXPECT_EQ(whole->get_header_value("Content-Type"), "video/mp4");
  EXPECT_EQ(whole->body, bytes);
  // What a video element asks for when it seeks: a range, answered 206 with just those bytes.
  auto part = client.Get("/api/jobs/" + *job_ + "/clip", {{"Range", "bytes=100-1099"}});
  ASSERT_TRUE(part);
  EXPECT_EQ(part->status, 206);
  EXPECT_EQ(part->body, bytes.substr(100, 1000));
  EXPECT_EQ(part->get_header_value("Content-Range"), "bytes 100-1099/" + std::to_string(bytes.size()));
  auto tail = client.Get("/api/jobs/" + *job_ + "/clip", {{"Range", "bytes=-10"}});
  ASSERT_TRUE(tail);
  EXPECT_EQ(tail->body, bytes.substr(bytes.size() - 10));

  auto poster = client.Get("/api/jobs/" + *job_ + "/poster");
  ASSERT_TRUE(poster);
  EXPECT_EQ(poster->status, 200);
  EXPECT_EQ(poster->get_header_value("Content-Type"), "image/jpeg");
  EXPECT_EQ(poster->body.substr(0, 2), "\xff\xd8");
  auto preview = client.Get("/api/jobs/" + *job_ + "/preview");
  ASSERT_TRUE(preview);
  EXPECT_EQ(preview->status, 200);
  EXPECT_EQ(preview->body.substr(8, 4), "WEBP");
}

TEST_F(HttpApiTest, PagesAndTheApiDocument) {
  httplib::Client client = camera_->Client();
  for (const EmbeddedFile& file : WebAssets()) {
    auto page = client.Get("/" + std::string(file.name));
    ASSERT_TRUE(page) << file.name;
    EXPECT_EQ(page->status, 200) << file.name;
    EXPECT_EQ(page->body, file.bytes) << file.name;
    EXPECT_THAT(page->get_header_value("Content-Security-Policy"), HasSubstr("default-src 'self'"));
  }
  auto index = client.Get("/");
  ASSERT_TRUE(index);
  EXPECT_THAT(index->body, HasSubstr("id=\"press\""));
  EXPECT_EQ(client.Get("/nothing-here.html")->status, 404);
  // Every path the API serves is in openapi.yaml.
  std::string yaml;
  for (const EmbeddedFile& file : WebAssets()) {
    if (file.name == "openapi.yaml") yaml = file.bytes;
  }
  for (const char* path : {"/api/status:",
                           "/api/jobs:",
                           "/api/press:",
                           "/api/jobs/{id}:",
                           "/api/jobs/{id}/cancel:",
                           "/api/jobs/{id}/clip:",
                           "/api/jobs/{id}/poster:",
                           "/api/jobs/{id}/preview:",
                           "/api/jobs/{id}/preview/map:",
                           "/api/settings:",
                           "/api/settings/move:",
                           "/api/settings/shot:",
                           "/api/events:",
                           "/api/login:",
                           "/api/logout:",
                           "/api/token.svg:"}) {
    EXPECT_THAT(yaml, HasSubstr(path));
  }
}

TEST_F(HttpApiTest, EveryMoveThePageOffersIsAccepted) {
  std::string index;
  for (const EmbeddedFile& file : WebAssets()) {
    if (file.name == "index.html") index = file.bytes;
  }
  // The moves of the settings' select and of the authoring page's region select.
  std::string moves;
  for (const char* select : {"<select id=\"setting-move\"", "<select id=\"author-region-move\""}) {
    const size_t start = index.find(select);
    ASSERT_NE(start, std::string::npos) << select;
    moves += index.substr(start, index.find("</select>", start) - start);
  }
  const std::regex option(R"rx(<option value="([a-z_0-9]+)")rx");
  int offered = 0;
  httplib::Client client = camera_->Client();
  for (auto it = std::sregex_iterator(moves.begin(), moves.end(), option); it != std::sregex_iterator(); ++it) {
    const std::string move = (*it)[1];
    auto set = client.Put("/api/settings/move", nlohmann::json({{"move", move}}).dump(), "application/json");
    ASSERT_TRUE(set);
    EXPECT_EQ(set->status, 200) << move << ": " << set->body;
    ++offered;
  }
  EXPECT_GE(offered, 13);
  auto bad = client.Put("/api/settings/move", R"({"move":"barrel_roll"})", "application/json");
  EXPECT_EQ(bad->status, 400);
  EXPECT_THAT(Json(bad)["error"].get<std::string>(), HasSubstr("barrel_roll"));
  EXPECT_EQ(client.Put("/api/settings/move", "not json", "application/json")->status, 400);
  EXPECT_EQ(client.Put("/api/settings/move", R"({"move":"auto"})", "application/json")->status, 200);
}

TEST_F(HttpApiTest, EverySettingThePageOffersIsAcceptedAndStatusShowsIt) {
  std::string index;
  for (const EmbeddedFile& file : WebAssets()) {
    if (file.name == "index.html") index = file.bytes;
  }
  httplib::Client client = camera_->Client();
  const std::regex option(R"rx(<option value="([a-z_0-9]*)")rx");
  for (const std::string field : {"effect", "format", "size"}) {
    const size_t start = index.find("<select id=\"setting-" + field + "\"");
    ASSERT_NE(start, std::string::npos) << field;
    const std::string select = index.substr(start, index.find("</select>", start) - start);
    int offered = 0;
    for (auto it = std::sregex_iterator(select.begin(), select.end(), option); it != std::sregex_iterator(); ++it) {
      const std::string value = (*it)[1];
      // "" is the page's "as configured": null in the API.
      const nlohmann::json wanted = value.empty() ? nlohmann::json(nullptr) : nlohmann::json(value);
      auto set = client.Put("/api/settings", nlohmann::json({{field, wanted}}).dump(), "application/json");
      ASSERT_TRUE(set);
      EXPECT_EQ(set->status, 200) << field << " " << value << ": " << set->body;
      EXPECT_EQ(Json(client.Get("/api/status"))["settings"][field], wanted) << field;
      ++offered;
    }
    EXPECT_GE(offered, 4) << field;
  }
  auto bad = client.Put("/api/settings", R"({"format":"avi"})", "application/json");
  ASSERT_TRUE(bad);
  EXPECT_EQ(bad->status, 400);
  EXPECT_THAT(Json(bad)["error"].get<std::string>(), HasSubstr("format: "));
  // The body cannot smuggle another command or a field the settings do not have.
  auto smuggled = client.Put("/api/settings", R"({"cmd":"quit","drain":true})", "application/json");
  ASSERT_TRUE(smuggled);
  EXPECT_EQ(smuggled->status, 400);
  EXPECT_EQ(Json(client.Get("/api/status"))["stopping"], false);
}

TEST_F(HttpApiTest, TraversalInEveryPathParameterFindsNothing) {
  httplib::Client client = camera_->Client();
  for (const char* path : {"/api/jobs/../../../etc/passwd",
                           "/api/jobs/%2e%2e/%2e%2e/etc/passwd",
                           "/api/jobs/..%2f..%2fetc%2fpasswd/clip",
                           "/api/jobs/"
                           "000001%2f..%2f..%2fjobs/clip",
                           "/api/jobs/1/../../http_token",
                           "/..%2f..%2fetc/passwd",
                           "/%2e%2e/%2e%2e/etc/passwd",
                           "/api/jobs/%00/clip",
                           "/api/jobs/1%00.mp4/clip",
                           "/login.html/../../http_token",
                           "/api/jobs/-1/poster",
                           "/api/jobs/1e3/preview"}) {
    auto reply = client.Get(path);
    ASSERT_TRUE(reply) << path;
    EXPECT_TRUE(reply->status == 404 || reply->status == 400) << path << " -> " << reply->status;
    EXPECT_THAT(reply->body, ::testing::Not(HasSubstr("root:"))) << path;
    EXPECT_THAT(reply->body, ::testing::Not(HasSubstr(camera_->http->token()))) << path;
  }
}

TEST_F(HttpApiTest, OversizedBodiesAndHeadersAreRefused) {
  httplib::Client client = camera_->Client();
  const std::string big(300 * 1024, 'x');
  auto body = client.Put("/api/settings/shot", big, "application/json");
  ASSERT_TRUE(body);
  EXPECT_EQ(body->status, 413);
  auto header = client.Get("/api/status", {{"X-Padding", std::string(20 * 1024, 'y')}});
  EXPECT_TRUE(!header || header->status >= 400) << (header ? header->status : 0);
  // Still serving.
  EXPECT_EQ(camera_->Client().Get("/api/status")->status, 200);
}

TEST_F(HttpApiTest, GarbageAndSlowClientsDoNotHurtOthers) {
  const int port = camera_->http->port();
  for (const std::string& garbage : {std::string("GARBAGE\r\n\r\n"),
                                     std::string("\x16\x03\x01\x02\x00\x01\x00", 7),
                                     std::string("GET /api/status HTTP/9.9\r\n\r\n"),
                                     std::string(5000, '\0'),
                                     std::string("POST /api/press HTTP/1.1\r\nContent-Length: -5\r\n\r\n")}) {
    const std::string reply = RawExchange(port, garbage, std::chrono::milliseconds(2000));
    EXPECT_THAT(reply, ::testing::Not(HasSubstr("202"))) << garbage.substr(0, 20);
  }
  // Clients that open a connection and send half a request line, then nothing.
  std::vector<std::thread> slow;
  for (int i = 0; i < 4; ++i) {
    slow.emplace_back([port] { RawExchange(port, "GET /api/sta", std::chrono::milliseconds(8000)); });
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  const auto start = std::chrono::steady_clock::now();
  auto status = camera_->Client().Get("/api/status");
  ASSERT_TRUE(status);
  EXPECT_EQ(status->status, 200);
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(3));
  for (std::thread& thread : slow) thread.join();
  EXPECT_EQ(Json(camera_->Client().Get("/api/jobs"))["jobs"].size(), 1u);  // nothing pressed, nothing lost
}

TEST_F(HttpApiTest, TwoHundredConcurrentClients) {
  std::atomic<int> ok{0};
  std::atomic<int> refused{0};
  std::atomic<int> other{0};
  std::vector<std::thread> clients;
  for (int i = 0; i < 200; ++i) {
    clients.emplace_back([&] {
      httplib::Client client = camera_->Client();
      auto reply = client.Get(i % 2 == 0 ? "/api/jobs" : "/");
      if (reply && reply->status == 200) {
        ++ok;
      } else if (reply && (reply->status == 503 || reply->status == 429)) {
        ++refused;
      } else {
        ++other;
      }
    });
  }
  for (std::thread& thread : clients) thread.join();
  EXPECT_EQ(other.load(), 0);
  EXPECT_GT(ok.load(), 50);
  EXPECT_EQ(ok.load() + refused.load(), 200);
  std::this_thread::sleep_for(std::chrono::seconds(2));  // the rate limit's bucket refills
  EXPECT_EQ(camera_->Client().Get("/api/status")->status, 200);
}

TEST_F(HttpApiTest, CrossOriginPressIsRefused) {
  httplib::Client client = camera_->Client();
  auto refused = client.Post("/api/press", {{"Origin", "http://evil.example"}}, "", "text/plain");
  ASSERT_TRUE(refused);
  EXPECT_EQ(refused->status, 403);
  auto cross_site = client.Delete("/api/jobs/" + *job_, {{"Sec-Fetch-Site", "cross-site"}});
  EXPECT_EQ(cross_site->status, 403);
  EXPECT_EQ(Json(client.Get("/api/jobs"))["jobs"].size(), 1u);
}

TEST_F(HttpApiTest, AnAuthoredShotRendersAsANewJob) {
  httplib::Client client = camera_->Client();
  auto shot = client.Get("/api/jobs/" + *job_ + "/shot");
  ASSERT_TRUE(shot);
  ASSERT_EQ(shot->status, 200);
  nlohmann::json edited = Json(shot);
  ASSERT_EQ(edited["format"], "parallax-shot");
  // Pull the end back to where the clip started, and focus there at 0.5 m.
  auto& keyframes = edited["segments"][0]["keyframes"];
  keyframes.back()["position_m"] = keyframes.front()["position_m"];
  keyframes.back()["aperture_m"] = 0.004;
  keyframes.back()["focus_depth_m"] = 0.5;

  EXPECT_EQ(
      client.Post("/api/jobs/" + *job_ + "/render", R"({"shot": {"format": "parallax-shot"}})", "application/json")
          ->status,
      400);
  EXPECT_EQ(
      client.Post("/api/jobs/424242/render", nlohmann::json({{"shot", edited}}).dump(), "application/json")->status,
      404);
  auto rendered =
      client.Post("/api/jobs/" + *job_ + "/render", nlohmann::json({{"shot", edited}}).dump(), "application/json");
  ASSERT_TRUE(rendered);
  ASSERT_EQ(rendered->status, 202) << rendered->body;
  const std::string id = Json(rendered)["job"];
  EXPECT_NE(id, *job_);
  nlohmann::json job;
  for (int i = 0; i < 1200; ++i) {
    job = Json(client.Get("/api/jobs/" + id))["job"];
    if (job["state"] == "done" || job["state"] == "failed") break;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  ASSERT_EQ(job["state"], "done") << job.dump();
  // The new clip was made from the same capture, with the shot as edited.
  nlohmann::json replayed = Json(client.Get("/api/jobs/" + id + "/shot"));
  const auto& last = replayed["segments"][0]["keyframes"].back();
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_NEAR(last["position_m"][axis].get<double>(), keyframes.front()["position_m"][axis].get<double>(), 1e-6);
  }
  EXPECT_NEAR(last["aperture_m"].get<double>(), 0.004, 1e-9);
  EXPECT_EQ(client.Delete("/api/jobs/" + id)->status, 200);
  EXPECT_TRUE(fs::exists(camera_->daemon->layout().CaptureDir(*job_) / "manifest.json"));  // the source's capture stays
}

// A preview viewpoint at the clip's own size, looking through `keyframe` (a shot's).
nlohmann::json ClipViewpoint(const nlohmann::json& camera_path, const nlohmann::json& keyframe) {
  const nlohmann::json& p = camera_path;
  return {{"keyframe", keyframe},
          {"width", p["width"]},
          {"height", p["height"]},
          {"clip",
           {{"width", p["width"]},
            {"height", p["height"]},
            {"cx", p["cx"]},
            {"cy", p["cy"]},
            {"aspect", p["aspect"]},
            {"output_scale", p["output_scale"]}}}};
}

TEST_F(HttpApiTest, ThePreviewMapsHVOverThePlaneTheCameraIsDraggedIn) {
  httplib::Client client = camera_->Client();
  const nlohmann::json shot = Json(client.Get("/api/jobs/" + *job_ + "/shot"));
  const nlohmann::json& start = shot["segments"][0]["keyframes"][0];
  const nlohmann::json path = Json(client.Get("/api/jobs/" + *job_))["report"]["camera_path"];
  const nlohmann::json viewpoint = ClipViewpoint(path, start);
  auto map = client.Post("/api/jobs/" + *job_ + "/preview/map",
                         nlohmann::json({{"viewpoint", viewpoint}, {"cells", 8}}).dump(),
                         "application/json");
  ASSERT_TRUE(map);
  ASSERT_EQ(map->status, 200) << map->body;
  const nlohmann::json body = Json(map);
  ASSERT_EQ(body["x_m"].size(), 8u);
  ASSERT_EQ(body["h_v"].size(), 8u);
  EXPECT_NEAR(body["z_m"].get<double>(), start["position_m"][2].get<double>(), 1e-9);
  int valid = 0;
  for (const nlohmann::json& row : body["h_v"]) {
    ASSERT_EQ(row.size(), 8u);
    for (const nlohmann::json& h : row) valid += h.get<double>() < body["valid_below"].get<double>();
  }
  // Near the lenses the views cover the frame; at twice their spread, turned the same way, not all.
  EXPECT_GT(valid, 0);
  EXPECT_LT(valid, 64);
  // The grid spans the lenses.
  const nlohmann::json scene = Json(client.Post("/api/jobs/" + *job_ + "/preview"))["scene"];
  for (const nlohmann::json& view : scene["views"]) {
    EXPECT_GT(view["centre_m"][0].get<double>(), body["x_m"][0].get<double>());
    EXPECT_LT(view["centre_m"][0].get<double>(), body["x_m"][7].get<double>());
  }
  auto bad = client.Post("/api/jobs/" + *job_ + "/preview/map",
                         nlohmann::json({{"viewpoint", viewpoint}, {"cells", 100}}).dump(),
                         "application/json");
  ASSERT_TRUE(bad);
  EXPECT_EQ(bad->status, 400);
  EXPECT_THAT(bad->body, HasSubstr("cells: want an integer in [3, 32]"));
  for (const nlohmann::json& cells : {nlohmann::json(2), nlohmann::json(4294967308), nlohmann::json(-3)}) {
    auto refused = client.Post("/api/jobs/" + *job_ + "/preview/map",
                               nlohmann::json({{"viewpoint", viewpoint}, {"cells", cells}}).dump(),
                               "application/json");
    ASSERT_TRUE(refused);
    EXPECT_EQ(refused->status, 400) << cells;
  }
}

TEST_F(HttpApiTest, APreviewWorkerOverItsMemoryLimitIsKilled) {
  PreviewOptions options;
  options.binary = BuiltWorkerFlags().worker_binary;
  options.config = DaemonConfigToJson(SmallConfig(dir_->path()));
  options.memory_limit_bytes = 4 << 20;  // less than any process that loads a capture needs
  StatusOr<std::unique_ptr<PreviewSession>> session =
      PreviewSession::Open(options, camera_->daemon->layout().CaptureDir(*job_));
  ASSERT_FALSE(session.ok());
  EXPECT_EQ(session.status().code(), StatusCode::kAborted) << session.status().ToString();
  EXPECT_THAT(session.status().message(), HasSubstr("over its limit of 4 MB (worker.memory_limit_mb); killed"));
}

TEST_F(HttpApiTest, APreviewWhoseWorkerIsGoneOpensAgainOnTheNextRequest) {
  PreviewOptions options;
  options.binary = BuiltWorkerFlags().worker_binary;
  options.config = DaemonConfigToJson(SmallConfig(dir_->path()));
  PreviewSessions sessions(options);
  const fs::path capture = camera_->daemon->layout().CaptureDir(*job_);
  StatusOr<std::shared_ptr<PreviewSession>> first = sessions.ForJob(*job_, capture);
  ASSERT_TRUE(first.ok()) << first.status().ToString();
  httplib::Client client = camera_->Client();
  const nlohmann::json path = Json(client.Get("/api/jobs/" + *job_))["report"]["camera_path"];
  const nlohmann::json shot = Json(client.Get("/api/jobs/" + *job_ + "/shot"));
  const nlohmann::json viewpoint = ClipViewpoint(path, shot["segments"][0]["keyframes"][0]);
  (*first)->Kill();  // as the memory limit or a missed deadline would
  StatusOr<PreviewFrame> lost = (*first)->Frame(viewpoint, false);
  ASSERT_FALSE(lost.ok());
  EXPECT_EQ(lost.status().code(), StatusCode::kUnavailable) << lost.status().ToString();
  EXPECT_EQ(sessions.Find(*job_), nullptr);
  StatusOr<std::shared_ptr<PreviewSession>> again = sessions.ForJob(*job_, capture);
  ASSERT_TRUE(again.ok()) << again.status().ToString();
  EXPECT_NE(again->get(), first->get());
  StatusOr<PreviewFrame> frame = (*again)->Frame(viewpoint, false);
  ASSERT_TRUE(frame.ok()) << frame.status().ToString();
  EXPECT_FALSE(frame->image.empty());
}

TEST_F(HttpApiTest, LivePreviewDrawsTheClipsFramesFromAnyViewpoint) {
  httplib::Client client = camera_->Client();
  auto opened = client.Post("/api/jobs/" + *job_ + "/preview");
  ASSERT_TRUE(opened);
  ASSERT_EQ(opened->status, 200) << opened->body;
  const nlohmann::json scene = Json(opened)["scene"];
  EXPECT_EQ(scene["views"].size(), 9u);
  EXPECT_GT(scene["depth_max_m"].get<double>(), scene["depth_min_m"].get<double>());

  // The clip's first frame, asked for at the clip's own size from the shot's first keyframe.
  const nlohmann::json details = Json(client.Get("/api/jobs/" + *job_));
  const nlohmann::json& path = details["report"]["camera_path"];
  const nlohmann::json shot = Json(client.Get("/api/jobs/" + *job_ + "/shot"));
  nlohmann::json viewpoint = ClipViewpoint(path, shot["segments"][0]["keyframes"][0]);
  // The viewpoint's frame with one of the request's flags set.
  auto frame_with = [&](const char* flag) {
    nlohmann::json flagged = viewpoint;
    flagged[flag] = true;
    return client.Post("/api/jobs/" + *job_ + "/preview/frame", flagged.dump(), "application/json");
  };
  auto frame = frame_with("coverage");
  ASSERT_TRUE(frame);
  ASSERT_EQ(frame->status, 200) << frame->body;
  EXPECT_EQ(frame->get_header_value("Content-Type"), "image/jpeg");
  const nlohmann::json figures = nlohmann::json::parse(frame->get_header_value("X-Preview"));
  // The clip's start is a valid viewpoint, judged as the planner judged it.
  EXPECT_TRUE(figures["valid"].get<bool>()) << figures.dump();
  EXPECT_LT(figures["h_v"].get<double>(), 2.0);
  cv::Mat preview = cv::imdecode(std::vector<uchar>(frame->body.begin(), frame->body.end()), cv::IMREAD_COLOR);
  auto video = px::testing::ProbeVideo(camera_->daemon->layout().FindClip(*job_));
  ASSERT_TRUE(video.ok()) << video.status().ToString();
  ASSERT_EQ(preview.size(), video->first_frame.size());
  EXPECT_GT(cv::PSNR(preview, video->first_frame), 30) << "the preview does not agree with the clip";

  // A click on the middle of the picture finds a scene point in front of the camera.
  auto probe = client.Post("/api/jobs/" + *job_ + "/preview/probe",
                           nlohmann::json({{"viewpoint", viewpoint}, {"x", 80}, {"y", 60}}).dump(),
                           "application/json");
  ASSERT_TRUE(probe);
  ASSERT_EQ(probe->status, 200) << probe->body;
  const double depth = Json(probe)["depth_m"];
  EXPECT_GT(depth, scene["depth_min_m"].get<double>() * 0.9);
  EXPECT_LT(depth, scene["depth_max_m"].get<double>() * 1.1);

  // Moved sideways by 2 cm, the picture changes.
  nlohmann::json moved = viewpoint;
  moved["keyframe"]["position_m"][0] = moved["keyframe"]["position_m"][0].get<double>() + 0.02;
  auto shifted = client.Post("/api/jobs/" + *job_ + "/preview/frame", moved.dump(), "application/json");
  ASSERT_TRUE(shifted);
  ASSERT_EQ(shifted->status, 200);
  EXPECT_NE(shifted->body, frame->body);

  // Lossless, the same picture as a PNG, with the camera it was drawn with.
  auto png = frame_with("lossless");
  ASSERT_TRUE(png);
  ASSERT_EQ(png->status, 200) << png->body;
  EXPECT_EQ(png->get_header_value("Content-Type"), "image/png");
  const nlohmann::json drawn = nlohmann::json::parse(png->get_header_value("X-Preview"))["camera"];
  EXPECT_EQ(drawn["width"].get<int>(), preview.cols);
  EXPECT_EQ(drawn["rotation"].size(), 9u);
  const cv::Mat exact = cv::imdecode(std::vector<uchar>(png->body.begin(), png->body.end()), cv::IMREAD_COLOR);
  ASSERT_EQ(exact.size(), preview.size());
  EXPECT_GT(cv::PSNR(exact, preview), 30) << "the PNG is not the JPEG's picture";

  // The scene for a renderer in the browser (pipeline/render/gl/web_scene.h).
  auto exported = client.Post("/api/jobs/" + *job_ + "/preview/scene");
  ASSERT_TRUE(exported);
  ASSERT_EQ(exported->status, 200) << exported->body;
  EXPECT_EQ(exported->get_header_value("Content-Type"), "application/octet-stream");
  ASSERT_GT(exported->body.size(), 9u * 160 * 120 * 16);
  EXPECT_EQ(exported->body.substr(0, 4), "PXWS");

  nlohmann::json bad = viewpoint;
  bad["width"] = 100000;
  auto refused = client.Post("/api/jobs/" + *job_ + "/preview/frame", bad.dump(), "application/json");
  EXPECT_EQ(refused->status, 400);
  EXPECT_THAT(refused->body, HasSubstr("pixels a side"));
  EXPECT_EQ(client.Delete("/api/jobs/" + *job_ + "/preview")->status, 200);
}

// Last: deletes the shared job.
TEST_F(HttpApiTest, ZDeleteRemovesEverything) {
  httplib::Client client = camera_->Client();
  const fs::path clip = camera_->daemon->layout().FindClip(*job_);
  const fs::path capture = camera_->daemon->layout().CaptureDir(*job_);
  ASSERT_TRUE(fs::exists(clip));
  auto deleted = client.Delete("/api/jobs/" + *job_);
  ASSERT_TRUE(deleted);
  EXPECT_EQ(deleted->status, 200) << deleted->body;
  EXPECT_FALSE(fs::exists(clip));
  EXPECT_FALSE(fs::exists(capture));
  EXPECT_FALSE(fs::exists(ClipPosterPathFor(clip)));
  EXPECT_EQ(client.Get("/api/jobs/" + *job_)->status, 404);
  EXPECT_EQ(client.Delete("/api/jobs/" + *job_)->status, 404);
  EXPECT_EQ(Json(client.Get("/api/jobs"))["jobs"].size(), 0u);
}

class HttpAccessTest : public px::testing::TempDirTest {};

TEST_F(HttpAccessTest, TokenRequiredAlways) {
  HttpServerOptions options;
  options.token_always = true;
  auto camera = Camera::Start(dir(), options);
  ASSERT_NE(camera, nullptr);
  httplib::Client client = camera->Client();
  const std::string token = camera->http->token();
  ASSERT_EQ(token.size(), 64u);

  EXPECT_EQ(client.Get("/api/jobs")->status, 401);
  EXPECT_EQ(client.Post("/api/press")->status, 401);
  auto page = client.Get("/");
  EXPECT_EQ(page->status, 302);
  EXPECT_EQ(page->get_header_value("Location"), "/login.html");
  EXPECT_EQ(client.Get("/login.html")->status, 200);
  EXPECT_EQ(client.Get("/api/jobs", {{"Authorization", "Bearer " + std::string(64, '0')}})->status, 401);
  EXPECT_EQ(client.Get("/api/jobs", {{"Authorization", "Bearer " + token}})->status, 200);

  EXPECT_EQ(client.Post("/api/login", R"({"token":"guess"})", "application/json")->status, 401);
  auto login = client.Post("/api/login", nlohmann::json({{"token", token}}).dump(), "application/json");
  ASSERT_TRUE(login);
  ASSERT_EQ(login->status, 200);
  const std::string cookie = login->get_header_value("Set-Cookie");
  EXPECT_THAT(cookie, HasSubstr("HttpOnly"));
  EXPECT_THAT(cookie, HasSubstr("SameSite=Strict"));
  const std::string pair = cookie.substr(0, cookie.find(';'));
  EXPECT_EQ(client.Get("/api/jobs", {{"Cookie", pair}})->status, 200);
  EXPECT_EQ(client.Get("/", {{"Cookie", pair}})->status, 200);
  // Nothing was pressed by the refused requests.
  EXPECT_EQ(Json(client.Get("/api/jobs", {{"Cookie", pair}}))["jobs"].size(), 0u);
}

TEST_F(HttpAccessTest, AnotherHostNeedsTheToken) {
  const std::string address = FirstNonLoopbackIpv4();
  if (address.empty()) GTEST_SKIP() << "this machine has no non-loopback IPv4 address to connect from";
  HttpServerOptions options;
  options.host = "0.0.0.0";
  auto camera = Camera::Start(dir(), options);
  ASSERT_NE(camera, nullptr);
  httplib::Client remote = camera->Client(address);
  auto refused = remote.Get("/api/jobs");
  ASSERT_TRUE(refused);
  EXPECT_EQ(refused->status, 401);
  EXPECT_EQ(remote.Post("/api/press")->status, 401);
  EXPECT_EQ(remote.Get("/api/jobs", {{"Authorization", "Bearer " + camera->http->token()}})->status, 200);
  EXPECT_EQ(remote.Get("/api/token.svg", {{"Authorization", "Bearer " + camera->http->token()}})->status, 403);
  // At the device: no token, and the QR code that carries it to a phone.
  httplib::Client local = camera->Client();
  EXPECT_EQ(local.Get("/api/jobs")->status, 200);
  auto qr = local.Get("/api/token.svg");
  ASSERT_TRUE(qr);
  EXPECT_EQ(qr->status, 200);
  EXPECT_THAT(qr->body, HasSubstr("<svg"));
  EXPECT_THAT(qr->get_header_value("X-Parallax-Login-Url"), HasSubstr("/login.html"));
}

TEST_F(HttpAccessTest, RateAndStreamLimits) {
  HttpServerOptions options;
  options.requests_per_s = 5;  // bursts of 10
  options.max_event_streams = 1;
  auto camera = Camera::Start(dir(), options);
  ASSERT_NE(camera, nullptr);
  httplib::Client client = camera->Client();
  int limited = 0;
  for (int i = 0; i < 30; ++i) {
    auto reply = client.Get("/api/status");
    ASSERT_TRUE(reply);
    if (reply->status == 429) {
      ++limited;
      EXPECT_EQ(reply->get_header_value("Retry-After"), "1");
    }
  }
  EXPECT_GE(limited, 15);
  std::this_thread::sleep_for(std::chrono::milliseconds(1200));  // five more requests' worth
  EXPECT_EQ(client.Get("/api/status")->status, 200);

  std::this_thread::sleep_for(std::chrono::seconds(2));
  EventReader first(*camera, [](const nlohmann::json&) { return false; });
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  auto second = camera->Client().Get("/api/events");
  ASSERT_TRUE(second);
  EXPECT_EQ(second->status, 503);
}

TEST_F(HttpAccessTest, PortInUseIsAClearError) {
  HttpServerOptions options;
  auto camera = Camera::Start(dir(), options);
  ASSERT_NE(camera, nullptr);
  auto daemon = BuildDaemon(SmallConfig(dir() / "second"), BuiltWorkerFlags());
  ASSERT_TRUE(daemon.ok());
  options.port = camera->http->port();
  options.token_path = dir() / "token2";
  HttpServer second(options, daemon->get());
  Status started = second.Start();
  ASSERT_FALSE(started.ok());
  EXPECT_THAT(started.message(), HasSubstr("127.0.0.1:" + std::to_string(options.port)));
}

}  // namespace
}  // namespace px::device
