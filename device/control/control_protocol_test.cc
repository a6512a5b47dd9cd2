#include "device/control/control_protocol.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

namespace px::device {
namespace {

using ::testing::HasSubstr;

TEST(ControlProtocolTest, ParsesEveryCommand) {
  EXPECT_EQ(ParseControlRequest(R"({"cmd":"capture"})")->command, ControlCommand::kCapture);
  EXPECT_EQ(ParseControlRequest(R"({"cmd":"status"})")->command, ControlCommand::kStatus);
  EXPECT_EQ(ParseControlRequest(R"( {"cmd" : "list"} )")->command, ControlCommand::kList);
  auto wait = ParseControlRequest(R"({"cmd":"wait","job":"000003"})");
  ASSERT_TRUE(wait.ok());
  EXPECT_EQ(wait->command, ControlCommand::kWait);
  EXPECT_EQ(wait->job, "000003");
  auto quit = ParseControlRequest(R"({"cmd":"quit","drain":true})");
  ASSERT_TRUE(quit.ok());
  EXPECT_TRUE(quit->drain);
  EXPECT_FALSE(ParseControlRequest(R"({"cmd":"quit"})")->drain);
  auto fetch = ParseControlRequest(R"({"cmd":"fetch","job":"000004","inline":true})");
  ASSERT_TRUE(fetch.ok()) << fetch.status().ToString();
  EXPECT_EQ(fetch->command, ControlCommand::kFetch);
  EXPECT_EQ(fetch->job, "000004");
  EXPECT_TRUE(fetch->inline_bytes);
  EXPECT_FALSE(ParseControlRequest(R"({"cmd":"fetch","job":"000004"})")->inline_bytes);
  auto move = ParseControlRequest(R"({"cmd":"set_move","move":"establishing_dolly"})");
  ASSERT_TRUE(move.ok());
  EXPECT_EQ(move->command, ControlCommand::kSetMove);
  EXPECT_EQ(move->move, "establishing_dolly");
  auto settings = ParseControlRequest(R"({"cmd":"set_settings","format":"gif","size":null})");
  ASSERT_TRUE(settings.ok()) << settings.status().ToString();
  EXPECT_EQ(settings->command, ControlCommand::kSetSettings);
  EXPECT_EQ(nlohmann::json::parse(settings->settings), nlohmann::json({{"format", "gif"}, {"size", nullptr}}));
  EXPECT_EQ(ParseControlRequest(R"({"cmd":"set_settings","format":["gif"]})").status().message(),
            "format: want a string or null, got array");
  EXPECT_EQ(ParseControlRequest(R"({"cmd":"set_settings","fps":60})").status().message(),
            "set_settings: unknown field 'fps'");
  auto cancel = ParseControlRequest(R"({"cmd":"cancel","job":"000002"})");
  ASSERT_TRUE(cancel.ok());
  EXPECT_EQ(cancel->command, ControlCommand::kCancel);
  EXPECT_EQ(cancel->job, "000002");
}

TEST(ControlProtocolTest, ErrorsSayWhatIsWrong) {
  EXPECT_THAT(ParseControlRequest("{\"cmd\":").status().message(), HasSubstr("request: malformed JSON at byte"));
  EXPECT_THAT(ParseControlRequest("capture").status().message(), HasSubstr("malformed JSON"));
  EXPECT_EQ(ParseControlRequest("[1]").status().message(), "request: want an object, got array");
  EXPECT_EQ(ParseControlRequest("{}").status().message(), "cmd: missing");
  EXPECT_EQ(ParseControlRequest(R"({"cmd":7})").status().message(), "cmd: want a string, got number");
  EXPECT_EQ(
      ParseControlRequest(R"({"cmd":"fly"})").status().message(),
      "cmd: 'fly' is not one of capture, status, list, wait, quit, fetch, set_move, cancel, set_shot, set_settings");
  EXPECT_EQ(ParseControlRequest(R"({"cmd":"fetch"})").status().message(), "job: missing (fetch needs a job id)");
  EXPECT_EQ(ParseControlRequest(R"({"cmd":"cancel"})").status().message(), "job: missing (cancel needs a job id)");
  EXPECT_EQ(ParseControlRequest(R"({"cmd":"set_move"})").status().message(),
            "move: missing (set_move needs a camera move)");
  EXPECT_EQ(ParseControlRequest(R"({"cmd":"fetch","job":"1","inline":1})").status().message(),
            "inline: want true or false, got number");
  EXPECT_EQ(ParseControlRequest(R"({"cmd":"cancel","job":"1","inline":true})").status().message(),
            "cancel: unknown field 'inline'");
  EXPECT_EQ(ParseControlRequest(R"({"cmd":"wait"})").status().message(), "job: missing (wait needs a job id)");
  EXPECT_EQ(ParseControlRequest(R"({"cmd":"capture","jbo":1})").status().message(), "capture: unknown field 'jbo'");
  EXPECT_EQ(ParseControlRequest(R"({"cmd":"quit","drain":"yes"})").status().message(),
            "drain: want true or false, got string");
  EXPECT_THAT(ParseControlRequest(std::string(kMaxControlLineBytes + 1, ' ')).status().message(),
              HasSubstr("is longer than"));
}

TEST(ControlProtocolTest, JobIdsAreDigitsOnlySoNoPathTrickReachesAFile) {
  for (const std::string& trick : {std::string("../000001"),
                                   std::string("/etc/passwd"),
                                   std::string("000001/../../x"),
                                   std::string(".."),
                                   std::string(""),
                                   std::string("000001.mp4"),
                                   std::string("0000001\0", 8),
                                   std::string(" 000001"),
                                   std::string("-1"),
                                   std::string("1234567890123456789")}) {
    for (const char* cmd : {"wait", "fetch", "cancel"}) {
      const nlohmann::json request = {{"cmd", cmd}, {"job", trick}};
      auto parsed = ParseControlRequest(request.dump());
      ASSERT_FALSE(parsed.ok()) << request.dump();
      EXPECT_EQ(parsed.status().code(), StatusCode::kInvalidArgument);
      EXPECT_THAT(parsed.status().message(), HasSubstr("is not a job id (1 to 18 digits")) << request.dump();
    }
  }
  EXPECT_EQ(ParseControlRequest(R"({"cmd":"fetch","job":"000042"})")->job, "000042");
  EXPECT_EQ(ParseControlRequest(R"({"cmd":"fetch","job":"123456789012345678"})")->job, "123456789012345678");
}

TEST(ControlProtocolTest, NumbersTooLargeForADoubleAreAnErrorNotACrash) {
  // Found by the control_request fuzzer: nlohmann's out_of_range escaped the parser.
  auto parsed = ParseControlRequest(R"({"cmd":"capture","x":9e9499})");
  ASSERT_FALSE(parsed.ok());
  EXPECT_EQ(parsed.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(parsed.status().message(), HasSubstr("number overflow parsing '9e9499'"));
}

TEST(ControlProtocolTest, ClientTextInErrorsIsCutShort) {
  const std::string long_name(5000, 'a');
  auto parsed = ParseControlRequest(R"({"cmd":")" + long_name + R"("})");
  ASSERT_FALSE(parsed.ok());
  EXPECT_LT(parsed.status().message().size(), 200u);
  EXPECT_THAT(parsed.status().message(), HasSubstr("...' (5000 bytes)"));
  const std::string reply = ControlErrorReply(InvalidArgumentError(std::string(100000, 'z')));
  EXPECT_LT(reply.size(), kMaxControlErrorBytes + 100);
  EXPECT_THAT(reply, HasSubstr("... (100000 bytes)"));
}

TEST(ControlProtocolTest, ErrorReplyIsOneJsonLine) {
  const std::string reply = ControlErrorReply(InvalidArgumentError("cmd: missing\nsecond line \xff"));
  EXPECT_EQ(reply.find('\n'), std::string::npos);
  auto j = nlohmann::json::parse(reply);
  EXPECT_EQ(j["ok"], false);
  EXPECT_EQ(j["code"], "INVALID_ARGUMENT");
  EXPECT_THAT(j["error"].get<std::string>(), HasSubstr("cmd: missing"));
}

}  // namespace
}  // namespace px::device
