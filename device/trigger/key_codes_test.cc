#include "device/trigger/key_codes.h"

#include <gtest/gtest.h>
#include <linux/input-event-codes.h>

namespace px::device {
namespace {

TEST(KeyCodes, NamesAndNumbers) {
  EXPECT_EQ(ParseKeyCode("KEY_CAMERA").value(), KEY_CAMERA);
  EXPECT_EQ(ParseKeyCode("KEY_ENTER").value(), KEY_ENTER);
  EXPECT_EQ(ParseKeyCode("BTN_0").value(), BTN_0);
  EXPECT_EQ(ParseKeyCode("212").value(), 212);
  EXPECT_EQ(KeyCodeName(KEY_CAMERA), "KEY_CAMERA");
  EXPECT_EQ(KeyCodeName(KEY_SPACE), "KEY_SPACE");
  EXPECT_EQ(KeyCodeName(0x2ff), "767");
}

TEST(KeyCodes, RefusesWhatIsNotAKey) {
  for (const char* bad : {"", "KEY_CAMRA", "key_camera", "-1", "12a", "100000"}) {
    auto code = ParseKeyCode(bad);
    EXPECT_FALSE(code.ok()) << bad;
    EXPECT_EQ(code.status().code(), StatusCode::kInvalidArgument) << bad;
  }
  EXPECT_NE(ParseKeyCode("KEY_CAMRA").status().message().find("'KEY_CAMRA' is not a known key name"),
            std::string::npos);
}

}  // namespace
}  // namespace px::device
