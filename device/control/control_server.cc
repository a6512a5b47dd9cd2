#include "device/control/control_server.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <deque>
#include <map>
#include <system_error>
#include <utility>
#include <vector>

#include "device/control/control_protocol.h"
#include "pipeline/core/log.h"

namespace px::device {

namespace fs = std::filesystem;

struct ControlServer::Shared {
  std::mutex mutex;
  bool closed = false;  // the server is gone: drop replies
  bool stop_requested = false;
  int wake_write = -1;
  std::deque<std::pair<uint64_t, std::string>> replies;  // (connection id, reply line)

  void Wake() {
    const char byte = 1;
    // A full pipe already guarantees a wake-up; nothing else can go wrong with a pipe we own.
    (void)!::write(wake_write, &byte, 1);
  }
};

namespace {

Status SocketError(const std::string& what, const fs::path& path, int err) {
  return UnavailableError("control socket " + path.string() + ": " + what + ": " + std::strerror(err));
}

bool FillAddress(const fs::path& path, sockaddr_un* address) {
  std::memset(address, 0, sizeof(*address));
  address->sun_family = AF_UNIX;
  const std::string text = path.string();
  if (text.size() >= sizeof(address->sun_path)) return false;
  std::memcpy(address->sun_path, text.c_str(), text.size() + 1);
  return true;
}

// True when a process accepts connections on `path` right now.
bool SomeoneListens(const sockaddr_un& address) {
  int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return false;
  const bool listening = ::connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) == 0;
  ::close(fd);
  return listening;
}

StatusOr<int> BindSocket(const fs::path& path, const ControlAccess& access) {
  sockaddr_un address;
  if (!FillAddress(path, &address)) {
    return InvalidArgumentError("control socket " + path.string() + ": path is longer than " +
                                std::to_string(sizeof(address.sun_path) - 1) + " bytes");
  }
  std::error_code ec;
  if (path.has_parent_path()) fs::create_directories(path.parent_path(), ec);
  if (ec) return SocketError("create folder " + path.parent_path().string(), path, ec.value());
  struct stat info {};
  if (::lstat(path.c_str(), &info) == 0) {
    if (!S_ISSOCK(info.st_mode)) {
      return FailedPreconditionError("control socket " + path.string() + ": exists and is not a socket");
    }
    if (SomeoneListens(address)) {
      return Status(StatusCode::kAlreadyExists,
                    "control socket " + path.string() + ": another process is listening there");
    }
    ::unlink(path.c_str());  // a stale socket left by a daemon that died
  }
  int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  if (fd < 0) return SocketError("socket", path, errno);
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) != 0) {
    int err = errno;
    ::close(fd);
    return SocketError("bind", path, err);
  }
  // Before listen(): until then every connect is refused, so no peer ever sees a looser mode.
  if (Status restricted = RestrictSocketFile(path, access); !restricted.ok()) {
    ::close(fd);
    ::unlink(path.c_str());
    return restricted;
  }
  if (::listen(fd, 16) != 0) {
    int err = errno;
    ::close(fd);
    ::unlink(path.c_str());
    return SocketError("listen", path, err);
  }
  return fd;
}

// Splits complete lines off the front of `buffer`; `\r\n` counts as a newline.
bool TakeLine(std::string* buffer, std::string* line) {
  size_t newline = buffer->find('\n');
  if (newline == std::string::npos) return false;
  *line = buffer->substr(0, newline);
  buffer->erase(0, newline + 1);
  if (!line->empty() && line->back() == '\r') line->pop_back();
  return true;
}

bool IsBlank(const std::string& line) { return line.find_first_not_of(" \t\r") == std::string::npos; }

// Answers a connection we will not serve with one error line and closes it.
void Refuse(int fd, const Status& status) {
  const std::string reply = ControlErrorReply(status) + "\n";
  (void)!::send(fd, reply.data(), reply.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
  ::close(fd);
}

}  // namespace

StatusOr<std::unique_ptr<ControlServer>> ControlServer::Open(const Options& options, Handlers handlers) {
  int listen_fd = -1;
  if (!options.socket_path.empty()) {
    PX_ASSIGN_OR_RETURN(listen_fd, BindSocket(options.socket_path, options.access));
  }
  int wake[2];
  if (::pipe2(wake, O_CLOEXEC | O_NONBLOCK) != 0) {
    int err = errno;
    if (listen_fd >= 0) ::close(listen_fd);
    return InternalError(std::string("control loop: pipe: ") + std::strerror(err));
  }
  return std::unique_ptr<ControlServer>(new ControlServer(options, std::move(handlers), listen_fd, wake[0], wake[1]));
}

ControlServer::ControlServer(const Options& options, Handlers handlers, int listen_fd, int wake_read, int wake_write)
    : options_(options),
      handlers_(std::move(handlers)),
      listen_fd_(listen_fd),
      wake_read_(wake_read),
      shared_(std::make_shared<Shared>()) {
  shared_->wake_write = wake_write;
}

ControlServer::~ControlServer() {
  Stop();
  {
    std::lock_guard<std::mutex> lock(shared_->mutex);
    shared_->closed = true;
    ::close(shared_->wake_write);
    shared_->wake_write = -1;
  }
  ::close(wake_read_);
  if (listen_fd_ >= 0) {
    ::close(listen_fd_);
    ::unlink(options_.socket_path.c_str());
  }
}

void ControlServer::Start() {
  PX_CHECK(!thread_.joinable()) << "ControlServer::Start called twice";
  thread_ = std::thread([this] { Loop(); });
}

void ControlServer::Stop() {
  std::lock_guard<std::mutex> stop_lock(stop_mutex_);
  if (stopped_) return;
  stopped_ = true;
  {
    std::lock_guard<std::mutex> lock(shared_->mutex);
    shared_->stop_requested = true;
    shared_->Wake();
  }
  if (thread_.joinable()) thread_.join();
}

struct ControlServer::Connection {
  int fd = -1;
  std::string in;
  std::string out;
  bool awaiting_reply = false;  // a request was handed out; read no further until it is answered
  bool peer_closed = false;     // the peer sent EOF (it may still read our replies)
  bool broken = false;          // an I/O error: close now
};

struct ControlServer::LoopState {
  std::map<uint64_t, Connection> connections;
  uint64_t next_id = 1;
  bool trigger_open = false;
  std::string trigger_buffer;  // a trigger line not yet ended by a newline
};

struct ControlServer::PollSet {
  std::vector<pollfd> fds;          // [0] the wake pipe, [1] the listening socket (when open), then:
  size_t trigger_index = 0;         // the trigger input, when open
  std::vector<size_t> input_index;  // per loop input, its fd's place (SIZE_MAX: none)
  size_t first_connection = 0;      // connections from here, in the order of `ids`
  std::vector<uint64_t> ids;
  int timeout_ms = -1;  // the nearest loop-input deadline; -1: none
};

void ControlServer::DeliverReplies(LoopState& state) {
  std::deque<std::pair<uint64_t, std::string>> replies;
  {
    std::lock_guard<std::mutex> lock(shared_->mutex);
    replies.swap(shared_->replies);
  }
  for (auto& [id, reply] : replies) {
    auto it = state.connections.find(id);
    if (it == state.connections.end()) continue;
    it->second.out += reply;
    it->second.out += '\n';
    it->second.awaiting_reply = false;
  }
}

// Hands out the next complete request of each idle connection.
void ControlServer::DispatchRequests(LoopState& state) {
  for (auto& [id, c] : state.connections) {
    std::string line;
    // One request at a time, and only once the last reply has gone out: a client that stops
    // reading gets nothing more served, so unsent replies cannot pile up in memory.
    while (!c.awaiting_reply && !c.broken && c.out.empty() && TakeLine(&c.in, &line)) {
      if (IsBlank(line)) continue;
      c.awaiting_reply = true;
      std::shared_ptr<Shared> shared = shared_;
      handlers_.on_request(line, [shared, id = id](const std::string& reply) {
        std::lock_guard<std::mutex> lock(shared->mutex);
        if (shared->closed) return;
        shared->replies.emplace_back(id, reply);
        shared->Wake();
      });
    }
    if (c.in.size() > kMaxControlLineBytes && c.in.find('\n') == std::string::npos) {
      // No newline within the limit: answer once and drop the connection's input.
      c.out += ControlErrorReply(InvalidArgumentError("request line longer than " +
                                                      std::to_string(kMaxControlLineBytes) + " bytes")) +
               "\n";
      c.in.clear();
      c.peer_closed = true;
    }
  }
}

ControlServer::PollSet ControlServer::BuildPollSet(LoopState& state) const {
  PollSet set;
  set.fds.push_back({wake_read_, POLLIN, 0});
  if (listen_fd_ >= 0) set.fds.push_back({listen_fd_, POLLIN, 0});
  set.trigger_index = set.fds.size();
  if (state.trigger_open) set.fds.push_back({options_.trigger_fd, POLLIN, 0});
  // Loop inputs: their fds, and the nearest deadline as poll's timeout.
  set.input_index.assign(options_.inputs.size(), SIZE_MAX);
  const auto now = std::chrono::steady_clock::now();
  for (size_t i = 0; i < options_.inputs.size(); ++i) {
    if (int fd = options_.inputs[i]->PollFd(); fd >= 0) {
      set.input_index[i] = set.fds.size();
      set.fds.push_back({fd, POLLIN, 0});
    }
    if (auto deadline = options_.inputs[i]->Deadline()) {
      const auto wait = std::chrono::ceil<std::chrono::milliseconds>(*deadline - now).count();
      const int wait_ms = static_cast<int>(std::clamp<int64_t>(wait, 0, INT32_MAX));
      set.timeout_ms = set.timeout_ms < 0 ? wait_ms : std::min(set.timeout_ms, wait_ms);
    }
  }
  set.first_connection = set.fds.size();
  for (auto& [id, c] : state.connections) {
    short events = 0;
    if (!c.peer_closed && !c.awaiting_reply && c.out.empty()) events |= POLLIN;
    if (!c.out.empty()) events |= POLLOUT;
    // A connection waiting for its reply is not polled: POLLHUP from a gone peer would spin.
    if (events == 0) continue;
    set.fds.push_back({c.fd, events, 0});
    set.ids.push_back(id);
  }
  return set;
}

void ControlServer::AcceptConnections(LoopState& state) {
  auto log = Logger("device");
  while (true) {
    int fd = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC | SOCK_NONBLOCK);
    if (fd < 0) break;
    StatusOr<PeerCredentials> peer = ReadPeerCredentials(fd);
    Status allowed = peer.ok() ? CheckPeer(*peer, options_.access) : peer.status();
    if (!allowed.ok()) {
      log->warn("control: refused a connection: {}", allowed.message());
      Refuse(fd, allowed);
      continue;
    }
    if (state.connections.size() >= kMaxControlConnections) {
      log->warn("control: refused a connection from pid {}: {} connections are open already",
                peer->pid,
                state.connections.size());
      Refuse(fd,
             ResourceExhaustedError("too many control connections (" + std::to_string(state.connections.size()) +
                                    " open, the limit is " + std::to_string(kMaxControlConnections) + ")"));
      continue;
    }
    Connection c;
    c.fd = fd;
    state.connections.emplace(state.next_id++, std::move(c));
  }
}

void ControlServer::ReadTrigger(LoopState& state) {
  char buffer[4096];
  ssize_t n = ::read(options_.trigger_fd, buffer, sizeof(buffer));
  if (n > 0) {
    state.trigger_buffer.append(buffer, static_cast<size_t>(n));
    std::string line;
    while (TakeLine(&state.trigger_buffer, &line)) handlers_.on_trigger(line);
  } else if (n == 0 || (errno != EINTR && errno != EAGAIN)) {
    if (n < 0) {
      Logger("device")->error("trigger input: read failed: {}; treating it as end of input", std::strerror(errno));
    }
    // A last line without a newline is still a press.
    if (!state.trigger_buffer.empty()) handlers_.on_trigger(state.trigger_buffer);
    state.trigger_buffer.clear();
    state.trigger_open = false;
    handlers_.on_trigger_eof();
  }
}

void ControlServer::ServiceLoopInputs(const PollSet& poll_set) {
  const auto now = std::chrono::steady_clock::now();
  for (size_t i = 0; i < options_.inputs.size(); ++i) {
    LoopInput& input = *options_.inputs[i];
    const short revents = poll_set.input_index[i] == SIZE_MAX ? 0 : poll_set.fds[poll_set.input_index[i]].revents;
    const auto deadline = input.Deadline();
    if (revents == 0 && !(deadline && now >= *deadline)) continue;
    const int presses = input.Service(now, revents);
    for (int k = 0; k < presses; ++k) handlers_.on_trigger(input.Describe());
  }
}

namespace {

// Sends what it can of a connection's output without blocking; an error other than a full
// buffer marks it broken.
template <typename Connection>
void FlushConnection(Connection& c) {
  while (!c.out.empty() && !c.broken) {
    ssize_t n = ::send(c.fd, c.out.data(), c.out.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n < 0) {
      if (errno == EINTR) continue;
      if (errno != EAGAIN && errno != EWOULDBLOCK) c.broken = true;
      return;
    }
    c.out.erase(0, static_cast<size_t>(n));
  }
}

// A connection's input after poll(): bytes read, EOF, or an error.
template <typename Connection>
void ReadConnection(const pollfd& p, Connection& c) {
  if (p.revents & POLLIN) {
    char buffer[4096];
    ssize_t n = ::recv(c.fd, buffer, sizeof(buffer), MSG_DONTWAIT);
    if (n > 0) {
      c.in.append(buffer, static_cast<size_t>(n));
    } else if (n == 0) {
      c.peer_closed = true;
    } else if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) {
      c.broken = true;
    }
  } else if (p.revents & (POLLERR | POLLNVAL)) {
    c.broken = true;
  } else if ((p.revents & POLLHUP) && !(p.events & POLLOUT)) {
    c.peer_closed = true;
  }
}

// Closes connections that broke, or whose peer is done and has every reply.
template <typename Connections>
void CloseFinished(Connections& connections) {
  for (auto it = connections.begin(); it != connections.end();) {
    auto& c = it->second;
    const bool finished = c.peer_closed && !c.awaiting_reply && c.out.empty();
    if (c.broken || finished) {
      ::close(c.fd);
      it = connections.erase(it);
    } else {
      ++it;
    }
  }
}

}  // namespace

void ControlServer::Loop() {
  LoopState state;
  state.trigger_open = options_.trigger_fd >= 0;
  while (true) {
    bool stop_requested;
    {
      std::lock_guard<std::mutex> lock(shared_->mutex);
      stop_requested = shared_->stop_requested;
    }
    DeliverReplies(state);
    // Flush first: a reply that has gone out lets that connection's next request through. Nothing
    // may flush after dispatching: a flush that empties a connection's output there would leave its
    // buffered requests waiting in `in` while poll() below waits for more input that never comes
    // (seen under load in peer_access_test). A reply made now comes back through the wake pipe.
    for (auto& [id, c] : state.connections) FlushConnection(c);
    DispatchRequests(state);
    CloseFinished(state.connections);
    if (stop_requested) break;

    PollSet poll_set = BuildPollSet(state);
    if (::poll(poll_set.fds.data(), poll_set.fds.size(), poll_set.timeout_ms) < 0) {
      if (errno == EINTR) continue;
      Logger("device")->error("control loop: poll failed: {}; control interface stopped", std::strerror(errno));
      break;
    }
    if (poll_set.fds[0].revents & POLLIN) {
      char drain[256];
      while (::read(wake_read_, drain, sizeof(drain)) > 0) {
      }
    }
    if (listen_fd_ >= 0 && (poll_set.fds[1].revents & POLLIN)) AcceptConnections(state);
    if (state.trigger_open && poll_set.fds[poll_set.trigger_index].revents != 0) ReadTrigger(state);
    ServiceLoopInputs(poll_set);
    for (size_t i = 0; i < poll_set.ids.size(); ++i) {
      ReadConnection(poll_set.fds[poll_set.first_connection + i], state.connections[poll_set.ids[i]]);
    }
  }
  // Last chance for replies already made (the answer to "quit"), then close everything.
  DeliverReplies(state);
  for (auto& [id, c] : state.connections) {
    FlushConnection(c);
    ::close(c.fd);
  }
}

}  // namespace px::device
