// Who may use the control socket, checked two ways: the rule itself (CheckPeer, ResolveGroup,
// ReadPeerCredentials on a real socket pair) and the real ControlServer against client
// processes running as another user (fork + setuid, so these need root; they skip otherwise):
// the file mode keeps strangers out, SO_PEERCRED refuses them even when the mode was loosened by
// hand, a configured group gets in (as primary or supplementary group), and the server's own
// limits (connections, unread replies) hold.
#include "device/control/peer_access.h"

#include <gmock/gmock.h>
#include <grp.h>
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cstring>
#include <thread>

#include "device/control/control_client.h"
#include "device/control/control_protocol.h"
#include "device/control/control_server.h"
#include "tests/testing/temp_dir.h"

namespace px::device {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

constexpr uid_t kNobody = 65534;
constexpr gid_t kNogroup = 65534;
constexpr gid_t kOtherGroup = 4242;  // a gid no test user belongs to

TEST(PeerAccessTest, OwnerAndRootAlwaysGroupOnlyWhenConfigured) {
  const ControlAccess owner_only{1000, std::nullopt};
  const ControlAccess with_group{1000, gid_t{300}};
  EXPECT_TRUE(CheckPeer({1, 1000, 1000, {}}, owner_only).ok());
  EXPECT_TRUE(CheckPeer({1, 0, 0, {}}, owner_only).ok());
  const Status stranger = CheckPeer({4242, 1001, 300, {300}}, owner_only);
  EXPECT_EQ(stranger.code(), StatusCode::kPermissionDenied);
  EXPECT_EQ(stranger.message(), "pid 4242 (uid 1001, gid 300) may not use the control socket: only uid 1000, root");
  EXPECT_TRUE(CheckPeer({1, 1001, 300, {}}, with_group).ok());         // primary group
  EXPECT_TRUE(CheckPeer({1, 1001, 100, {27, 300}}, with_group).ok());  // supplementary group
  EXPECT_THAT(CheckPeer({1, 1001, 100, {27}}, with_group).message(), HasSubstr("only uid 1000, root and group 300"));
}

TEST(PeerAccessTest, ResolvesGroupNamesAndNumbers) {
  EXPECT_EQ(ResolveGroup("0").value(), 0u);
  EXPECT_EQ(ResolveGroup("4242").value(), 4242u);  // a gid need not have a name
  if (const group* root = ::getgrgid(0)) {
    EXPECT_EQ(ResolveGroup(root->gr_name).value(), 0u);
  }
  const auto missing = ResolveGroup("px-no-such-group");
  EXPECT_EQ(missing.status().code(), StatusCode::kNotFound);
  EXPECT_EQ(missing.status().message(), "control.group: 'px-no-such-group': no such group");
  EXPECT_EQ(ResolveGroup("").status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(ResolveGroup("99999999999").status().code(), StatusCode::kInvalidArgument);
}

TEST(PeerAccessTest, ReadsTheCredentialsOfTheOtherEnd) {
  int fds[2];
  ASSERT_EQ(::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, fds), 0);
  auto peer = ReadPeerCredentials(fds[0]);
  ::close(fds[0]);
  ::close(fds[1]);
  ASSERT_TRUE(peer.ok()) << peer.status().ToString();
  EXPECT_EQ(peer->pid, ::getpid());
  EXPECT_EQ(peer->uid, ::geteuid());
  EXPECT_EQ(peer->gid, ::getegid());
}

// What a client process running as another user saw.
enum ClientOutcome {
  kServed = 0,         // connected and got an ok reply
  kConnectDenied = 1,  // connect() failed with EACCES: the file mode kept it out
  kRefused = 2,        // connected, then got PERMISSION_DENIED and the connection closed
  kOther = 3,
};

// Forks a client that becomes uid/gid (with `groups` as supplementary groups), connects to
// `socket`, sends a status request and reports what happened as its exit code. Only
// async-signal-safe calls after fork (the parent has threads).
ClientOutcome RunClientAs(const fs::path& socket, uid_t uid, gid_t gid, std::vector<gid_t> groups) {
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  std::strncpy(address.sun_path, socket.c_str(), sizeof(address.sun_path) - 1);
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (::setgroups(groups.size(), groups.data()) != 0 || ::setgid(gid) != 0 || ::setuid(uid) != 0) ::_exit(kOther);
    const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
    if (::connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) != 0) {
      ::_exit(errno == EACCES ? kConnectDenied : kOther);
    }
    const char request[] = "{\"cmd\":\"status\"}\n";
    // The server may have refused and closed before the request goes out (EPIPE, never
    // SIGPIPE); its reply is still there to read.
    (void)!::send(fd, request, sizeof(request) - 1, MSG_NOSIGNAL);
    char reply[1024] = {0};
    size_t got = 0;
    while (got < sizeof(reply) - 1) {
      const ssize_t n = ::read(fd, reply + got, sizeof(reply) - 1 - got);
      if (n <= 0) break;
      got += static_cast<size_t>(n);
      if (std::memchr(reply, '\n', got) != nullptr) break;
    }
    if (std::strstr(reply, "\"ok\":true") != nullptr) ::_exit(kServed);
    if (std::strstr(reply, "PERMISSION_DENIED") != nullptr) ::_exit(kRefused);
    ::_exit(kOther);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) ? static_cast<ClientOutcome>(WEXITSTATUS(status)) : kOther;
}

class ControlServerAccessTest : public ::testing::Test {
 protected:
  void SetUp() override {
    // Other users must be able to reach the socket's folder, or the folder and not the socket
    // would keep them out.
    ASSERT_EQ(::chmod(temp_.path().c_str(), 0755), 0);
  }
  fs::path SocketPath() const { return temp_.path() / "ctl.sock"; }

  std::unique_ptr<ControlServer> Serve(std::optional<gid_t> group) {
    ControlServer::Options options;
    options.socket_path = SocketPath();
    options.access = OwnerAccess(group);
    ControlServer::Handlers handlers;
    handlers.on_request = [this](const std::string&, ControlServer::Respond respond) {
      served_++;
      respond(R"({"ok":true})");
    };
    handlers.on_trigger = [](const std::string&) {};
    handlers.on_trigger_eof = [] {};
    auto server = ControlServer::Open(options, std::move(handlers));
    EXPECT_TRUE(server.ok()) << server.status().ToString();
    if (!server.ok()) return nullptr;
    (*server)->Start();
    return std::move(server).value();
  }

  std::atomic<int> served_{0};

 private:
  px::testing::TempDir temp_;
};

TEST_F(ControlServerAccessTest, SocketIsOwnerOnlyAndStrangersAreKeptOut) {
  auto server = Serve(std::nullopt);
  ASSERT_NE(server, nullptr);
  struct stat info {};
  ASSERT_EQ(::stat(SocketPath().c_str(), &info), 0);
  EXPECT_EQ(info.st_mode & 07777, 0600u);
  EXPECT_EQ(info.st_uid, ::geteuid());
  if (::geteuid() != 0) GTEST_SKIP() << "acting as another user needs root; the mode was checked";
  EXPECT_EQ(RunClientAs(SocketPath(), kNobody, kNogroup, {}), kConnectDenied);
  EXPECT_EQ(served_.load(), 0);
  // The owner (root here) is served.
  auto client = ControlClient::Connect(SocketPath());
  ASSERT_TRUE(client.ok());
  EXPECT_EQ((*client)->Call(R"({"cmd":"status"})").value(), R"({"ok":true})");
}

TEST_F(ControlServerAccessTest, PeerCredentialsRefuseStrangersEvenWhenTheModeWasLoosened) {
  if (::geteuid() != 0) GTEST_SKIP() << "acting as another user needs root";
  auto server = Serve(std::nullopt);
  ASSERT_NE(server, nullptr);
  ASSERT_EQ(::chmod(SocketPath().c_str(), 0666), 0);  // an administrator's mistake
  EXPECT_EQ(RunClientAs(SocketPath(), kNobody, kNogroup, {}), kRefused);
  EXPECT_EQ(served_.load(), 0);
}

TEST_F(ControlServerAccessTest, ConfiguredGroupGetsInAsPrimaryOrSupplementaryGroup) {
  auto server = Serve(kNogroup);
  ASSERT_NE(server, nullptr);
  struct stat info {};
  ASSERT_EQ(::stat(SocketPath().c_str(), &info), 0);
  EXPECT_EQ(info.st_mode & 07777, 0660u);
  EXPECT_EQ(info.st_gid, kNogroup);
  if (::geteuid() != 0) GTEST_SKIP() << "acting as another user needs root; the mode was checked";
  EXPECT_EQ(RunClientAs(SocketPath(), kNobody, kNogroup, {}), kServed);
  EXPECT_EQ(RunClientAs(SocketPath(), kNobody, kOtherGroup, {kNogroup}), kServed);
  EXPECT_EQ(RunClientAs(SocketPath(), kNobody, kOtherGroup, {}), kConnectDenied);
  ASSERT_EQ(::chmod(SocketPath().c_str(), 0666), 0);
  EXPECT_EQ(RunClientAs(SocketPath(), kNobody, kOtherGroup, {}), kRefused);
  EXPECT_EQ(served_.load(), 2);
}

TEST_F(ControlServerAccessTest, ConnectionsBeyondTheLimitAreRefused) {
  auto server = Serve(std::nullopt);
  ASSERT_NE(server, nullptr);
  std::vector<std::unique_ptr<ControlClient>> clients;
  for (size_t i = 0; i < kMaxControlConnections; ++i) {
    auto client = ControlClient::Connect(SocketPath());
    ASSERT_TRUE(client.ok());
    clients.push_back(std::move(client).value());
  }
  // Each of them is being served: the server has accepted every one.
  for (auto& client : clients) ASSERT_TRUE(client->Call(R"({"cmd":"status"})").ok());
  auto extra = ControlClient::Connect(SocketPath());
  ASSERT_TRUE(extra.ok());
  auto refused = (*extra)->ReadLine(std::chrono::seconds(10));
  ASSERT_TRUE(refused.ok()) << refused.status().ToString();
  EXPECT_THAT(*refused, HasSubstr("RESOURCE_EXHAUSTED"));
  EXPECT_THAT(*refused, HasSubstr("too many control connections"));
  clients.pop_back();  // one closes; a new one gets in
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  auto next = ControlClient::Connect(SocketPath());
  ASSERT_TRUE(next.ok());
  EXPECT_TRUE((*next)->Call(R"({"cmd":"status"})").ok());
}

TEST_F(ControlServerAccessTest, AClientThatDoesNotReadGetsNoMoreServed) {
  ControlServer::Options options;
  options.socket_path = SocketPath();
  const std::string big(256 * 1024, 'x');  // each reply fills the socket's buffer on its own
  ControlServer::Handlers handlers;
  handlers.on_request = [&](const std::string& line, ControlServer::Respond respond) {
    served_++;
    respond(R"({"ok":true,"n":")" + line.substr(0, 8) + R"(","pad":")" + big + R"("})");
  };
  handlers.on_trigger = [](const std::string&) {};
  handlers.on_trigger_eof = [] {};
  auto server = ControlServer::Open(options, std::move(handlers));
  ASSERT_TRUE(server.ok());
  (*server)->Start();
  auto client = ControlClient::Connect(SocketPath()).value();
  constexpr int kRequests = 40;
  std::string requests;
  for (int i = 0; i < kRequests; ++i) requests += std::to_string(10000000 + i) + "\n";
  ASSERT_TRUE(client->SendRaw(requests).ok());
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  // The first reply cannot be fully sent while nobody reads, so at most one more is taken.
  EXPECT_LE(served_.load(), 2);
  for (int i = 0; i < kRequests; ++i) {
    auto reply = client->ReadLine(std::chrono::seconds(20));
    ASSERT_TRUE(reply.ok()) << i << ": " << reply.status().ToString();
    EXPECT_EQ(reply->substr(0, 25), R"({"ok":true,"n":")" + std::to_string(10000000 + i) + "\"") << i;
  }
  EXPECT_EQ(served_.load(), kRequests);
}

}  // namespace
}  // namespace px::device
