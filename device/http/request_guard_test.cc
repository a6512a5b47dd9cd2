// Who may do what over HTTP: the access rules decided from a request's facts.
#include "device/http/request_guard.h"

#include <gtest/gtest.h>

#include "device/http/access_token.h"
#include "tests/testing/temp_dir.h"

namespace px::device {
namespace {

constexpr char kToken[] = "00112233445566778899aabbccddeeff00112233445566778899aabbccddeeff";

RequestFacts AtTheDevice(const std::string& method, const std::string& path) {
  RequestFacts facts;
  facts.method = method;
  facts.path = path;
  facts.remote_address = "127.0.0.1";
  facts.host = "127.0.0.1:8080";
  return facts;
}

RequestFacts FromThePhone(const std::string& method, const std::string& path) {
  RequestFacts facts = AtTheDevice(method, path);
  facts.remote_address = "192.168.1.23";
  facts.host = "192.168.1.10:8080";
  return facts;
}

AccessPolicy Policy(bool always = false) { return {kToken, always}; }

TEST(RequestGuardTest, LoopbackAddressesAndHosts) {
  for (const char* address : {"127.0.0.1", "127.1.2.3", "::1", "::ffff:127.0.0.1"}) {
    EXPECT_TRUE(IsLoopbackAddress(address)) << address;
  }
  for (const char* address : {"192.168.1.2", "10.0.0.1", "::ffff:10.0.0.1", "fe80::1", "", "localhost", "127.0.0.1x"}) {
    EXPECT_FALSE(IsLoopbackAddress(address)) << address;
  }
  for (const char* host : {"localhost", "LOCALHOST:8080", "127.0.0.1:80", "[::1]:8080", "[::1]"}) {
    EXPECT_TRUE(IsLoopbackHost(host)) << host;
  }
  for (const char* host : {"evil.example:8080", "192.168.1.10:8080", "localhost.evil.example", "[fe80::1]:80", ""}) {
    EXPECT_FALSE(IsLoopbackHost(host)) << host;
  }
}

TEST(RequestGuardTest, TokenFromBearerOrCookie) {
  EXPECT_EQ(PresentedToken("Bearer abc", ""), "abc");
  EXPECT_EQ(PresentedToken("", "theme=dark; px_token=abc; other=1"), "abc");
  EXPECT_EQ(PresentedToken("Basic abc", "px_tokenx=1"), "");
  EXPECT_EQ(PresentedToken("", ""), "");
}

TEST(RequestGuardTest, TheDeviceItselfNeedsNoTokenUnlessAlways) {
  EXPECT_TRUE(DecideAccess(AtTheDevice("GET", "/api/jobs"), Policy()).Allowed());
  EXPECT_TRUE(DecideAccess(AtTheDevice("POST", "/api/press"), Policy()).Allowed());
  EXPECT_EQ(DecideAccess(AtTheDevice("GET", "/api/jobs"), Policy(/*always=*/true)).status, 401);
}

TEST(RequestGuardTest, OthersShowTheToken) {
  RequestFacts facts = FromThePhone("GET", "/api/jobs");
  EXPECT_EQ(DecideAccess(facts, Policy()).status, 401);
  facts.authorization = std::string("Bearer ") + kToken;
  EXPECT_TRUE(DecideAccess(facts, Policy()).Allowed());
  facts.authorization = "Bearer 00112233445566778899aabbccddeeff00112233445566778899aabbccddeefe";
  EXPECT_EQ(DecideAccess(facts, Policy()).status, 401);
  facts.authorization.clear();
  facts.cookie = std::string("px_token=") + kToken;
  EXPECT_TRUE(DecideAccess(facts, Policy()).Allowed());
}

TEST(RequestGuardTest, DnsRebindingNeedsTheToken) {
  // A page from evil.example whose name now resolves to 127.0.0.1: loopback peer, foreign Host.
  RequestFacts facts = AtTheDevice("GET", "/api/jobs");
  facts.host = "evil.example:8080";
  EXPECT_EQ(DecideAccess(facts, Policy()).status, 401);
}

TEST(RequestGuardTest, LoginPageIsOpenToAll) {
  EXPECT_TRUE(DecideAccess(FromThePhone("GET", "/login.html"), Policy()).Allowed());
  EXPECT_TRUE(DecideAccess(FromThePhone("GET", "/login.js"), Policy()).Allowed());
  EXPECT_TRUE(DecideAccess(FromThePhone("POST", "/api/login"), Policy()).Allowed());
  EXPECT_EQ(DecideAccess(FromThePhone("GET", "/"), Policy()).status, 401);
  EXPECT_EQ(DecideAccess(FromThePhone("GET", "/app.js"), Policy()).status, 401);
}

TEST(RequestGuardTest, ForeignOriginsCannotChangeState) {
  RequestFacts facts = FromThePhone("POST", "/api/press");
  facts.authorization = std::string("Bearer ") + kToken;
  facts.origin = "http://192.168.1.10:8080";
  EXPECT_TRUE(DecideAccess(facts, Policy()).Allowed());
  for (const char* origin : {"http://evil.example", "null", "http://192.168.1.10:8081", "http://192.168.1.10"}) {
    facts.origin = origin;
    EXPECT_EQ(DecideAccess(facts, Policy()).status, 403) << origin;
  }
  // Even at the device, and even for the login call.
  RequestFacts local = AtTheDevice("DELETE", "/api/jobs/000001");
  local.origin = "http://evil.example";
  EXPECT_EQ(DecideAccess(local, Policy()).status, 403);
  RequestFacts login = FromThePhone("POST", "/api/login");
  login.fetch_site = "cross-site";
  EXPECT_EQ(DecideAccess(login, Policy()).status, 403);
  // Reading is not changing state: a GET with a foreign Origin is judged by its token alone.
  RequestFacts read = AtTheDevice("GET", "/api/jobs");
  read.origin = "http://evil.example";
  EXPECT_TRUE(DecideAccess(read, Policy()).Allowed());
}

class AccessTokenTest : public px::testing::TempDirTest {};

TEST_F(AccessTokenTest, MadeOnceKeptPrivate) {
  const auto path = dir() / "http_token";
  auto first = LoadOrCreateAccessToken(path);
  ASSERT_TRUE(first.ok()) << first.status().ToString();
  EXPECT_EQ(first->size(), 64u);  // 256 bits
  auto second = LoadOrCreateAccessToken(path);
  ASSERT_TRUE(second.ok());
  EXPECT_EQ(*first, *second);
  EXPECT_EQ(std::filesystem::status(path).permissions() & std::filesystem::perms::all,
            std::filesystem::perms::owner_read | std::filesystem::perms::owner_write);
  auto other = LoadOrCreateAccessToken(dir() / "other_token");
  ASSERT_TRUE(other.ok());
  EXPECT_NE(*first, *other);
  EXPECT_TRUE(TokensEqual(*first, *second));
  EXPECT_FALSE(TokensEqual(*first, *other));
}

TEST_F(AccessTokenTest, GarbledFileIsAnErrorNamingIt) {
  const auto path = dir() / "http_token";
  std::FILE* file = std::fopen(path.c_str(), "w");
  std::fputs("not a token\n", file);
  std::fclose(file);
  auto token = LoadOrCreateAccessToken(path);
  ASSERT_FALSE(token.ok());
  EXPECT_NE(token.status().message().find(path.string()), std::string::npos) << token.status().ToString();
}

}  // namespace
}  // namespace px::device
